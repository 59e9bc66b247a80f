#pragma once

#include <limits>
// The Reflection Probes dock's own editors beyond the parameter rows: the probe inspector. A probe
// chosen by number, or by a click on its marker in the viewport, shows its six faces as a cube
// cross (mip 0 of a cube map, the face colours of the faces encoding) in the viewport's display
// encoding, with its position, box and face colours, and whether the simvx box records carry it
// (a check box that edits reflection_probes.simvx_subset as one undoable change).

#include <memory>

#include <QImage>
#include <QWidget>

#include "bake/ReflectionBake.h"

class QCheckBox;
class QLabel;
class QSpinBox;

namespace terralux {

class ProjectDocument;

class ReflectionPanel : public QWidget {
    Q_OBJECT
public:
    explicit ReflectionPanel(ProjectDocument* doc, QWidget* parent = nullptr);
    // The probes the viewport draws (null: none bound).
    void setProbes(std::shared_ptr<const ReflectionProbeSet> set, const QString& source);
    // Shows probe `index` (scene order); out-of-range indices are clamped.
    void inspect(int index);
    int inspected() const;
    // The cube cross of the inspected probe (null image without probes).
    const QImage& crossImage() const { return cross_; }
    // The viewport's exposure as shown now (ProjectRenderer::shownEv100), which a metered mode
    // moves: the image follows it.
    void setShownEv100(double ev100);

signals:
    void rejected(const QString& message);

private:
    void refresh();
    ProjectDocument* doc_;
    double shownEv100_ = std::numeric_limits<double>::quiet_NaN();
    std::shared_ptr<const ReflectionProbeSet> set_;
    QString source_;
    QSpinBox* probe_;
    QLabel *status_, *image_, *info_;
    QCheckBox* inSimvx_;
    QImage cross_;
    bool refreshing_ = false;
};

// The six faces of probe `index` as a horizontal cross (−X +Z +X −Z in the middle row, +Y above
// and −Y below +Z), `faceSize` pixels a face, exposed by `exposure` (cameraExposureScale) and display-encoded as
// the viewport encodes (ACES fit, sRGB).
QImage reflectionCross(const ReflectionProbeSet& set, size_t index, int faceSize, double exposure);

}  // namespace terralux
