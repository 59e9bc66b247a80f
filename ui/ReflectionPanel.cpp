#include "ReflectionPanel.h"

#include <algorithm>
#include <cmath>

#include <QCheckBox>
#include <QFormLayout>
#include <QLabel>
#include <QPixmap>
#include <QSpinBox>
#include <QVBoxLayout>

#include "ProjectDocument.h"
#include "DisplayEncoding.h"
#include "scene/Exposure.h"

namespace terralux {
namespace {

const char* kFaceNames[6] = {"+X", "-X", "+Y", "-Y", "+Z", "-Z"};

}  // namespace

QImage reflectionCross(const ReflectionProbeSet& set, size_t index, int faceSize, double exposureScale) {
    QImage img(4 * faceSize, 3 * faceSize, QImage::Format_RGB32);
    img.fill(QColor(40, 40, 40));
    if (index >= set.probes.size()) return img;
    const ReflectionProbe& p = set.probes[index];
    const float exposure = float(exposureScale);
    // Cell (column, row) of each face in the cross; the faces meet seamlessly in this layout.
    const int cell[6][2] = {{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {3, 1}};
    const bool cube = set.encoding == ReflectionEncoding::Cubemap && !p.texels.empty();
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < faceSize; ++y)
            for (int x = 0; x < faceSize; ++x) {
                glm::vec3 c = p.faces[size_t(f)];
                if (cube) {
                    const int tx = x * set.faceSize / faceSize, ty = y * set.faceSize / faceSize;
                    c = p.texels[set.texelOffset(0, f) + size_t(ty) * size_t(set.faceSize) + size_t(tx)];
                }
                c *= exposure;
                img.setPixel(cell[f][0] * faceSize + x, cell[f][1] * faceSize + y,
                             qRgb(displayByte(c.x), displayByte(c.y), displayByte(c.z)));
            }
    return img;
}

ReflectionPanel::ReflectionPanel(ProjectDocument* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
    auto* v = new QVBoxLayout(this);
    v->setContentsMargins(0, 0, 0, 0);
    auto* form = new QFormLayout;
    probe_ = new QSpinBox;
    probe_->setObjectName("reflection.probe");
    probe_->setToolTip("The probe to inspect, in scene order (row-major, x fastest); a click on a "
                       "reflection-probe marker in the viewport picks it too");
    form->addRow("Inspect probe", probe_);
    v->addLayout(form);
    status_ = new QLabel;
    status_->setObjectName("reflection.status");
    status_->setWordWrap(true);
    v->addWidget(status_);
    image_ = new QLabel;
    image_->setObjectName("reflection.inspector");
    image_->setToolTip("The probe's six faces as a cube cross: -X +Z +X -Z across, +Y above and -Y "
                       "below +Z; mip 0 of a cube map, or the face colours, in the viewport's exposure");
    v->addWidget(image_);
    info_ = new QLabel;
    info_->setObjectName("reflection.probeInfo");
    info_->setWordWrap(true);
    info_->setTextInteractionFlags(Qt::TextSelectableByMouse);
    v->addWidget(info_);
    inSimvx_ = new QCheckBox("In the simvx box records");
    inSimvx_->setObjectName("reflection.inSimvx");
    inSimvx_->setToolTip("The simvx runtime holds 8 probes: checked probes make up "
                         "reflection_probes.simvx_subset (none checked: the first 8)");
    v->addWidget(inSimvx_);

    connect(probe_, &QSpinBox::valueChanged, this, [this] {
        if (!refreshing_) refresh();
    });
    connect(inSimvx_, &QCheckBox::toggled, this, [this](bool on) {
        if (refreshing_) return;
        const ReflectionProbeSettings& s = doc_->project().scene.reflectionProbes;
        const int index = probe_->value();
        // The subset as it stands; an empty one means the first 8, so make that explicit first.
        std::vector<int> subset = s.simvxSubset;
        const int count = s.gridDims[0] * s.gridDims[1];
        if (subset.empty())
            for (int i = 0; i < std::min(count, kSimvxMaxProbes); ++i) subset.push_back(i);
        const auto it = std::find(subset.begin(), subset.end(), index);
        if (on && it == subset.end()) subset.push_back(index);
        if (!on && it != subset.end()) subset.erase(it);
        std::sort(subset.begin(), subset.end());
        QString error;
        if (!doc_->setParameter("reflection_probes.simvx_subset", subset, &error)) {
            emit rejected(error);
            refresh();
        }
    });
    connect(doc_, &ProjectDocument::parametersChanged, this, [this](const QString& path) {
        if (path.isEmpty() || path.startsWith("reflection_probes") || path.startsWith("camera")) refresh();
    });
    refresh();
}

void ReflectionPanel::setProbes(std::shared_ptr<const ReflectionProbeSet> set, const QString& source) {
    set_ = std::move(set);
    source_ = source;
    refresh();
}

void ReflectionPanel::inspect(int index) { probe_->setValue(index); }

int ReflectionPanel::inspected() const { return probe_->value(); }

void ReflectionPanel::setShownEv100(double ev100) {
    // Redrawn only for a change a viewer could see, not for each adapting frame's hundredth of a stop.
    if (std::isfinite(ev100) == std::isfinite(shownEv100_) && (!std::isfinite(ev100) || std::abs(ev100 - shownEv100_) < 0.05)) return;
    shownEv100_ = ev100;
    refresh();
}

void ReflectionPanel::refresh() {
    refreshing_ = true;
    const ReflectionProbeSettings& s = doc_->project().scene.reflectionProbes;
    const int count = set_ ? int(set_->probes.size()) : 0;
    probe_->setRange(0, std::max(count - 1, 0));
    probe_->setEnabled(count > 0);
    const int index = probe_->value();
    if (!s.enabled) status_->setText("Reflection probes are off.");
    else if (!set_) status_->setText("No probes yet: the preview is baking them.");
    else status_->setText(QString("%1 probes (%2)").arg(count).arg(source_));
    if (set_ && index < count) {
        cross_ = reflectionCross(*set_, size_t(index), 48, cameraExposureScale(doc_->project().scene.camera, shownEv100_));
        image_->setPixmap(QPixmap::fromImage(cross_));
        // Held at the cross's size, so the dock's scrolled page makes room for all of it at once
        // (until its layout caught up, the label kept the height it had empty).
        image_->setMinimumSize(cross_.size());
        const ReflectionProbe& p = set_->probes[size_t(index)];
        QString faces;
        for (int f = 0; f < 6; ++f)
            faces += QString("%1 %2 %3 %4%5")
                         .arg(kFaceNames[f])
                         .arg(p.faces[size_t(f)].x, 0, 'f', 3)
                         .arg(p.faces[size_t(f)].y, 0, 'f', 3)
                         .arg(p.faces[size_t(f)].z, 0, 'f', 3)
                         .arg(f % 2 ? "\n" : ";  ");
        info_->setText(QString("id %1 at (%2, %3, %4) m\nbox half extents (%5, %6, %7) m\nface radiance:\n%8")
                           .arg(p.id)
                           .arg(p.position.x, 0, 'f', 1).arg(p.position.y, 0, 'f', 1).arg(p.position.z, 0, 'f', 1)
                           .arg(p.halfExtent.x, 0, 'f', 1).arg(p.halfExtent.y, 0, 'f', 1).arg(p.halfExtent.z, 0, 'f', 1)
                           .arg(faces.trimmed()));
        const bool carried = s.simvxSubset.empty()
                                 ? index < kSimvxMaxProbes
                                 : std::find(s.simvxSubset.begin(), s.simvxSubset.end(), index) != s.simvxSubset.end();
        inSimvx_->setChecked(carried);
        inSimvx_->setEnabled(s.enabled);
    } else {
        cross_ = QImage();
        image_->clear();
        image_->setMinimumSize(0, 0);
        info_->clear();
        inSimvx_->setChecked(false);
        inSimvx_->setEnabled(false);
    }
    refreshing_ = false;
}

}  // namespace terralux
