#include "ProbeInspector.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <QComboBox>
#include <QFormLayout>
#include <QLabel>
#include <QPixmap>
#include <QSpinBox>
#include <QVBoxLayout>

#include "ProjectDocument.h"
#include "DisplayEncoding.h"
#include "bake/SphericalHarmonics.h"
#include "scene/Exposure.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace terralux {
namespace {

// (l, m) of coefficient k = l(l + 1) + m.
QString bandOf(int k) {
    const int l = k == 0 ? 0 : k < 4 ? 1 : 2;
    return QString("l%1 m%2").arg(l).arg(k - l * (l + 1), 2);
}

}  // namespace

glm::vec3 probeIrradiance(const GpuProbeVolume& v, size_t probe, const glm::vec3& n) {
    sh::ShRgb c;
    for (int k = 0; k < 9; ++k) c.c[k] = v.coeffs.at(probe)[size_t(k)];
    const glm::vec3 e = v.irradianceEncoded ? sh::evalRadiance(c, n) : sh::evalIrradiance(c, n);
    return glm::max(e * v.scale, glm::vec3(0.0f));
}

QImage irradianceBall(const GpuProbeVolume& v, size_t probe, int size, double exposureScale) {
    QImage img(size, size, QImage::Format_RGB32);
    img.fill(QColor(40, 40, 40));
    if (probe >= v.coeffs.size()) return img;
    const float exposure = float(exposureScale);
    const float r = 0.5f * float(size);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const float u = (float(x) + 0.5f - r) / r, w = (r - float(y) - 0.5f) / r;
            const float z2 = 1.0f - u * u - w * w;
            if (z2 < 0.0f) continue;
            // Seen from +Z (the south): the visible hemisphere faces +Z.
            const glm::vec3 L = probeIrradiance(v, probe, glm::vec3(u, w, std::sqrt(z2))) *
                                (exposure / std::numbers::pi_v<float>);
            img.setPixel(x, y, qRgb(displayByte(L.x), displayByte(L.y), displayByte(L.z)));
        }
    return img;
}

ProbeWeights probeWeightsAt(const std::vector<GpuProbeVolume>& volumes, const glm::vec3& p) {
    ProbeWeights out;
    for (size_t vi = 0; vi < volumes.size(); ++vi) {
        const GpuProbeVolume& v = volumes[vi];
        const glm::ivec3 dims(v.dims);
        if (v.occupancy.empty() || dims.x <= 0 || dims.y <= 0 || dims.z <= 0) continue;
        const glm::vec3 lo = v.origin, hi = lo + v.spacing * glm::vec3(v.dims);
        const glm::vec3 q = glm::clamp(p, lo, hi);
        const float dist = glm::length(p - q);
        const float fade = dist <= 0.0f ? 1.0f
                           : v.fallbackBlendDistance > 0.0f ? std::clamp(1.0f - dist / v.fallbackBlendDistance, 0.0f, 1.0f)
                                                             : 0.0f;
        if (fade <= 0.0f) continue;
        const glm::vec3 g = (q - lo) / v.spacing - 0.5f;
        const glm::ivec3 c0(glm::floor(g));
        const glm::vec3 f = g - glm::vec3(c0);
        for (int climb = 0; climb < dims.y + 1; ++climb) {
            std::vector<std::pair<int, float>> found;
            float sum = 0.0f;
            for (int k = 0; k < 8; ++k) {
                const glm::ivec3 o(k & 1, (k >> 1) & 1, (k >> 2) & 1);
                const glm::ivec3 c = glm::clamp(c0 + o + glm::ivec3(0, climb, 0), glm::ivec3(0), dims - 1);
                const int probe = v.occupancy[size_t(c.x) + size_t(c.y) * size_t(dims.x) + size_t(c.z) * size_t(dims.x) * size_t(dims.y)];
                if (probe < 0) continue;
                const glm::vec3 wv = glm::mix(glm::vec3(1.0f) - f, f, glm::vec3(o));
                const float w = std::max(wv.x * wv.y * wv.z, 1e-6f);
                const auto same = std::find_if(found.begin(), found.end(), [&](const auto& e) { return e.first == probe; });
                if (same != found.end()) same->second += w;
                else found.emplace_back(probe, w);
                sum += w;
            }
            if (sum <= 0.0f) continue;
            for (auto& e : found) e.second /= sum;
            std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) {
                return a.second != b.second ? a.second > b.second : a.first < b.first;
            });
            out.volume = int(vi);
            out.probes = std::move(found);
            return out;
        }
    }
    return out;
}

ErrorNearby errorAround(const ErrorMap& map, const glm::vec3& position, float radius) {
    ErrorNearby out;
    if (map.empty() || !(map.step > 0.0f)) return out;
    const int i0 = std::max(0, int(std::floor((position.x - radius - map.x0) / map.step)));
    const int i1 = std::min(int(map.nx) - 1, int(std::ceil((position.x + radius - map.x0) / map.step)));
    const int j0 = std::max(0, int(std::floor((position.z - radius - map.z0) / map.step)));
    const int j1 = std::min(int(map.nz) - 1, int(std::ceil((position.z + radius - map.z0) / map.step)));
    double sum = 0.0;
    for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
            const float e = map.error[size_t(j) * map.nx + size_t(i)];
            const float dx = map.x0 + float(i) * map.step - position.x, dz = map.z0 + float(j) * map.step - position.z;
            if (!std::isfinite(e) || dx * dx + dz * dz > radius * radius) continue;
            ++out.points;
            sum += e;
            out.max = std::max(out.max, e);
        }
    if (out.points) out.mean = float(sum / double(out.points));
    return out;
}

ProbeInspector::ProbeInspector(ProjectDocument* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
    auto* v = new QVBoxLayout(this);
    v->setContentsMargins(0, 0, 0, 0);
    auto* form = new QFormLayout;
    volume_ = new QComboBox;
    volume_->setObjectName("probeInspector.volume");
    volume_->setToolTip("The volume whose probe to inspect, among those the viewport lights with");
    form->addRow("Inspect volume", volume_);
    probe_ = new QSpinBox;
    probe_->setObjectName("probeInspector.probe");
    probe_->setToolTip("The probe, in the order of its .shprobe records; a click on a probe marker in "
                       "the viewport (overlay \"Probe positions\") picks it too");
    form->addRow("Inspect probe", probe_);
    v->addLayout(form);
    status_ = new QLabel;
    status_->setObjectName("probeInspector.status");
    status_->setWordWrap(true);
    v->addWidget(status_);
    point_ = new QLabel;
    point_->setObjectName("probeInspector.point");
    point_->setWordWrap(true);
    point_->setToolTip("A click on the terrain: the probes the viewport blends there, with their weights");
    point_->hide();
    v->addWidget(point_);
    image_ = new QLabel;
    image_->setObjectName("probeInspector.ball");
    image_->setToolTip("A white diffuse ball lit by this probe alone, seen from the south (east to the "
                       "right), in the viewport's exposure");
    v->addWidget(image_);
    info_ = new QLabel;
    info_->setObjectName("probeInspector.info");
    info_->setWordWrap(true);
    info_->setTextInteractionFlags(Qt::TextSelectableByMouse);
    info_->setFont(QFont("monospace"));
    v->addWidget(info_);

    connect(volume_, &QComboBox::currentIndexChanged, this, [this] {
        if (!refreshing_) refresh();
    });
    connect(probe_, &QSpinBox::valueChanged, this, [this] {
        if (!refreshing_) refresh();
    });
    // The ball follows the exposure.
    connect(doc_, &ProjectDocument::parametersChanged, this, [this](const QString& path) {
        if (path.isEmpty() || path.startsWith("camera")) refresh();
    });
    refresh();
}

void ProbeInspector::setVolumes(std::shared_ptr<const std::vector<GpuProbeVolume>> volumes, const QString& source) {
    volumes_ = std::move(volumes);
    source_ = source;
    refreshing_ = true;
    const QString keep = volume_->currentText();
    volume_->clear();
    if (volumes_)
        for (const GpuProbeVolume& g : *volumes_) volume_->addItem(QString::fromStdString(g.name));
    if (const int i = volume_->findText(keep); i >= 0) volume_->setCurrentIndex(i);
    refreshing_ = false;
    refresh();
}

void ProbeInspector::inspect(int volume, int probe) {
    refreshing_ = true;
    volume_->setCurrentIndex(std::clamp(volume, 0, std::max(volume_->count() - 1, 0)));
    refreshing_ = false;
    refresh();
    probe_->setValue(probe);
}

void ProbeInspector::showPoint(std::optional<glm::vec3> point) {
    point_->setVisible(point.has_value());
    if (!point) return;
    const ProbeWeights w = volumes_ ? probeWeightsAt(*volumes_, *point) : ProbeWeights{};
    QString text = QString("Terrain at (%1, %2, %3) m: ").arg(point->x, 0, 'f', 1).arg(point->y, 0, 'f', 1).arg(point->z, 0, 'f', 1);
    if (w.volume < 0) {
        point_->setText(text + "no volume's probes light it (the sky's light alone)");
        return;
    }
    QStringList parts;
    for (const auto& [probe, weight] : w.probes) parts << QString("probe %1 × %2").arg(probe).arg(weight, 0, 'f', 3);
    point_->setText(text + QString("lit by '%1': ").arg(QString::fromStdString((*volumes_)[size_t(w.volume)].name)) +
                    parts.join(", "));
    inspect(w.volume, w.probes.front().first);
}

void ProbeInspector::setShownEv100(double ev100) {
    // Redrawn only for a change a viewer could see, not for each adapting frame's hundredth of a stop.
    if (std::isfinite(ev100) == std::isfinite(shownEv100_) && (!std::isfinite(ev100) || std::abs(ev100 - shownEv100_) < 0.05)) return;
    shownEv100_ = ev100;
    refresh();
}

void ProbeInspector::refresh() {
    refreshing_ = true;
    const int vi = volume_->currentIndex();
    const GpuProbeVolume* g = volumes_ && vi >= 0 && size_t(vi) < volumes_->size() ? &(*volumes_)[size_t(vi)] : nullptr;
    const int count = g ? int(g->coeffs.size()) : 0;
    probe_->setRange(0, std::max(count - 1, 0));
    probe_->setEnabled(count > 0);
    volume_->setEnabled(volume_->count() > 1);
    const int index = probe_->value();
    if (!volumes_ || volumes_->empty()) status_->setText("No probes yet: bake, or wait for the draft preview.");
    else status_->setText(QString("%1 probes (%2)").arg(count).arg(source_));
    if (g && index < count) {
        ball_ = irradianceBall(*g, size_t(index), 128, cameraExposureScale(doc_->project().scene.camera, shownEv100_));
        image_->setPixmap(QPixmap::fromImage(ball_));
        const glm::vec3 up = probeIrradiance(*g, size_t(index), glm::vec3(0, 1, 0));
        const glm::vec3 down = probeIrradiance(*g, size_t(index), glm::vec3(0, -1, 0));
        const auto rgb = [](const glm::vec3& c) {
            return QString("%1 %2 %3").arg(c.x, 8, 'f', 4).arg(c.y, 8, 'f', 4).arg(c.z, 8, 'f', 4);
        };
        QString text;
        const ProbeDiagnostics* d = g->diagnostics ? &*g->diagnostics : nullptr;
        if (d && size_t(index) < d->positions.size()) {
            const glm::vec3 p = d->positions[size_t(index)];
            text += QString("at (%1, %2, %3) m, %4\n")
                        .arg(p.x, 0, 'f', 1).arg(p.y, 0, 'f', 1).arg(p.z, 0, 'f', 1)
                        .arg(d->moved[size_t(index)] ? "moved up out of the terrain" : "valid where placed");
            if (size_t(index) < d->standardError.size())
                text += QString("standard error %1 % of its irradiance\n").arg(100.0 * d->standardError[size_t(index)], 0, 'f', 2);
            // Around it: the map's points within one occupancy cell, where this probe's light
            // dominates the lookup.
            const ErrorNearby near = errorAround(d->errorMap, p, g->spacing);
            if (near.points)
                text += QString("interpolation error within %1 m: mean %2 %, max %3 % (%4 points)\n")
                            .arg(g->spacing, 0, 'f', 0).arg(100.0 * near.mean, 0, 'f', 1)
                            .arg(100.0 * near.max, 0, 'f', 1).arg(near.points);
            else if (!d->errorMap.empty())
                text += QString("no error-map point within %1 m\n").arg(g->spacing, 0, 'f', 0);
        }
        text += "E up   " + rgb(up) + "\nE down " + rgb(down) + "\n";
        text += g->irradianceEncoded ? "SH (irradiance, Â·L):\n" : "SH (radiance L):\n";
        for (int k = 0; k < 9; ++k) text += bandOf(k) + "  " + rgb(g->coeffs[size_t(index)][size_t(k)]) + "\n";
        info_->setText(text.trimmed());
    } else {
        ball_ = QImage();
        image_->clear();
        info_->clear();
    }
    refreshing_ = false;
}

}  // namespace terralux
