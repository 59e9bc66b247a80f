#pragma once

#include <limits>
// The Probe Volumes dock's inspector of one diffuse probe of the volumes the viewport lights with
// (the last bake or the draft preview): its irradiance on a white diffuse ball and as numbers
// (the nine SH coefficients, E on level ground facing up and facing down), its standard error,
// whether it was moved up out of the terrain, and the interpolation error the error map measured
// around it. A probe is chosen by volume and number, or by a click on its marker in the viewport
// (MainWindow::diffuseProbeAt).

#include <cstddef>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include <QImage>
#include <QWidget>

#include <glm/vec3.hpp>

#include "render/TerrainRenderer.h"

class QComboBox;
class QLabel;
class QSpinBox;

namespace terralux {

class ProjectDocument;

class ProbeInspector : public QWidget {
    Q_OBJECT
public:
    explicit ProbeInspector(ProjectDocument* doc, QWidget* parent = nullptr);
    // The volumes the viewport lights with (ProjectRenderer::boundVolumes) and where they came from.
    void setVolumes(std::shared_ptr<const std::vector<GpuProbeVolume>> volumes, const QString& source);
    // Shows probe `probe` (record order of its .shprobe) of bound volume `volume`; clamped.
    void inspect(int volume, int probe);
    // The lit ball of the inspected probe (null image without probes).
    const QImage& ballImage() const { return ball_; }
    // A terrain point clicked in the viewport: says which probes light it with their weights and
    // inspects the heaviest; nullopt clears the line (a marker was clicked instead).
    void showPoint(std::optional<glm::vec3> point);

    // The viewport's exposure as shown now (ProjectRenderer::shownEv100), which a metered mode
    // moves: the image follows it.
    void setShownEv100(double ev100);

private:
    void refresh();
    ProjectDocument* doc_;
    double shownEv100_ = std::numeric_limits<double>::quiet_NaN();
    std::shared_ptr<const std::vector<GpuProbeVolume>> volumes_;
    QString source_;
    QComboBox* volume_;
    QSpinBox* probe_;
    QLabel *status_, *point_, *image_, *info_;
    QImage ball_;
    bool refreshing_ = false;
};

// Irradiance of probe `probe` of `v` on a surface with unit normal n, as the viewport evaluates
// it (docs/lighting.md, "Engine lookup"): the coefficients (pre-convolved or convolved here),
// times the file's default SH scale, clamped at 0.
glm::vec3 probeIrradiance(const GpuProbeVolume& v, size_t probe, const glm::vec3& n);

// A white diffuse ball of `size` pixels lit by the probe alone: radiance E(n)/π at the normal n
// of each pixel, seen from the south (+Z) with east (+X) to the right and up (+Y) up, exposed by
// 2^exposureEv and display-encoded as the viewport encodes. Pixels off the ball are dark grey.
QImage irradianceBall(const GpuProbeVolume& v, size_t probe, int size, double exposure);

// The probes the viewport blends at `p` (shaders/probes.glsl, probeIrradiance, mirrored here):
// the first volume whose fallback fade is above 0; the 8 cell centres around p clamped into its
// grid, cells without a probe left out, each corner's trilinear weight at least 1e-6, climbing a
// layer at a time while no corner has a probe. Weights renormalised to sum to 1, a probe that
// several corners name counted once with their sum, heaviest first; no volume: volume -1.
struct ProbeWeights {
    int volume = -1;
    std::vector<std::pair<int, float>> probes;  // record, weight
};
ProbeWeights probeWeightsAt(const std::vector<GpuProbeVolume>& volumes, const glm::vec3& p);

// The error map's covered points within `radius` metres (horizontally) of `position`.
struct ErrorNearby {
    size_t points = 0;
    float mean = 0.0f, max = 0.0f;
};
ErrorNearby errorAround(const ErrorMap& map, const glm::vec3& position, float radius);

}  // namespace terralux
