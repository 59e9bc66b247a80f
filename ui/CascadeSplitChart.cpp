#include "CascadeSplitChart.h"

#include <algorithm>
#include <cmath>

#include <QLocale>
#include <QMouseEvent>
#include <QPainter>

#include "ProjectDocument.h"

namespace terralux {

namespace {

// The cascade view's colours (shaders/views.glsl, viewCascades), cascades 0-3.
const QColor kCascadeColours[4] = {QColor::fromRgbF(0.90f, 0.25f, 0.20f), QColor::fromRgbF(0.25f, 0.75f, 0.25f),
                                   QColor::fromRgbF(0.25f, 0.45f, 0.95f), QColor::fromRgbF(0.95f, 0.85f, 0.20f)};

constexpr int kPad = 8;    // strip inset from the widget's sides
constexpr int kGrip = 5;   // handle grip height above the strip
constexpr int kReach = 6;  // pixels from a handle that still grab it

// Axis labels: metres below a kilometre, three significant digits of kilometres above.
QString axisText(double m) {
    if (m < 1000.0) return QString::number(m, 'f', m < 10.0 ? 1 : 0) + " m";
    return QString::number(m / 1000.0, 'g', 3) + " km";
}

// Split labels: metres, as the splits are authored.
QString splitText(double m) { return QLocale().toString(m, 'f', m < 10.0 ? 1 : 0) + " m"; }

// Whether `box`, widened by `margin` each side, overlaps any of `placed`.
bool overlaps(const std::vector<QRect>& placed, const QRect& box, int margin) {
    return std::any_of(placed.begin(), placed.end(),
                       [&](const QRect& q) { return q.adjusted(-margin, 0, margin, 0).intersects(box); });
}

// A 1-2-5 step giving about `count` ticks over `span`.
double tickStep(double span, int count) {
    const double raw = span / std::max(count, 1);
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    const double r = raw / mag;
    return mag * (r < 1.5 ? 1.0 : r < 3.5 ? 2.0 : r < 7.5 ? 5.0 : 10.0);
}

}  // namespace

CascadeSplitChart::CascadeSplitChart(ProjectDocument* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
    setObjectName("shadows.splitChart");
    setMouseTracking(true);
    setSizePolicy(QSizePolicy::Expanding, QSizePolicy::Fixed);
    connect(doc_, &ProjectDocument::parametersChanged, this, &CascadeSplitChart::refresh);
    connect(doc_, &ProjectDocument::terrainChanged, this, &CascadeSplitChart::refresh);
    connect(doc_, &ProjectDocument::viewChanged, this, &CascadeSplitChart::refresh);
    refresh();
}

bool CascadeSplitChart::manual() const {
    const ShadowSettings& s = doc_->project().scene.shadows;
    return s.enabled && s.splitMode == SplitMode::Manual && s.cascades > 1 && s.splits &&
           int(s.splits->size()) == s.cascades - 1;
}

void CascadeSplitChart::refresh() {
    ShadowSettings s = doc_->project().scene.shadows;
    // An undo or another edit during a drag ends it where the splits it held no longer apply.
    if (dragging_ >= 0 && (!manual() || dragSplits_.size() != s.splits->size())) dragging_ = -1;
    if (dragging_ >= 0) s.splits = dragSplits_;
    range_ = doc_->shadowRange(s);
    const QString what = "Where each cascade ends, in metres from the camera along its view (the project "
                         "camera at the viewport's aspect).\n";
    if (!s.enabled) setToolTip(what + "Sun shadows are off: no cascades are drawn.");
    else if (s.cascades < 2) setToolTip(what + "One cascade covers the whole range: there is no split to move.");
    else if (!manual())
        setToolTip(what + "Split mode practical places the splits from Split lambda, and they follow the view; "
                          "set Split mode to manual to drag them.");
    else
        setToolTip(what + "Drag a split to move it. Splits stay in order and below the shadow distance.");
    update();
}

QSize CascadeSplitChart::minimumSizeHint() const {
    const int fh = fontMetrics().height();
    // Split labels in two rows above the strip, axis labels in one below.
    return {240, 2 + 2 * fh + kGrip + 2 + std::max(14, fh) + 6 + fh + 2};
}

QSize CascadeSplitChart::sizeHint() const { return {320, minimumSizeHint().height()}; }

QRect CascadeSplitChart::strip() const {
    const int fh = fontMetrics().height();
    return {kPad, 2 + 2 * fh + kGrip + 2, std::max(1, width() - 2 * kPad), std::max(14, fh)};
}

double CascadeSplitChart::xOf(double d) const {
    const QRect r = strip();
    const double span = std::max(range_.farDistance - range_.nearDistance, 1e-9);
    return r.left() + (d - range_.nearDistance) / span * r.width();
}

double CascadeSplitChart::distanceAt(double x) const {
    const QRect r = strip();
    return range_.nearDistance + (x - r.left()) / std::max(r.width(), 1) * (range_.farDistance - range_.nearDistance);
}

QPoint CascadeSplitChart::handlePosition(int i) const {
    if (i < 0 || i + 1 >= int(range_.ends.size())) return {};
    return {int(std::lround(xOf(range_.ends[size_t(i)]))), strip().center().y()};
}

int CascadeSplitChart::handleAt(double x) const {
    int best = -1;
    double bestDistance = kReach + 0.5;
    for (int i = 0; i + 1 < int(range_.ends.size()); ++i) {
        const double d = std::abs(xOf(range_.ends[size_t(i)]) - x);
        // Handles on top of each other: the later one when pressing right of them.
        if (d < bestDistance || (d == bestDistance && x > xOf(range_.ends[size_t(i)]))) {
            best = i;
            bestDistance = d;
        }
    }
    return best;
}

void CascadeSplitChart::changeEvent(QEvent* e) {
    if (e->type() == QEvent::FontChange) updateGeometry();
    QWidget::changeEvent(e);
}

void CascadeSplitChart::paintEvent(QPaintEvent*) {
    QPainter p(this);
    p.setRenderHint(QPainter::Antialiasing);
    const ShadowSettings& s = doc_->project().scene.shadows;
    if (!s.enabled) p.setOpacity(0.4);
    const QFontMetrics fm = fontMetrics();
    const int fh = fm.height();
    const QRect r = strip();
    const QColor text = palette().color(QPalette::WindowText);

    // The cascades, numbered where they are wide enough.
    double from = range_.nearDistance;
    for (size_t i = 0; i < range_.ends.size(); ++i) {
        const double x0 = xOf(from), x1 = xOf(range_.ends[i]);
        const QRectF seg(x0, r.top(), x1 - x0, r.height());
        const QColor c = kCascadeColours[std::min<size_t>(i, 3)];
        p.fillRect(seg, c);
        const QString n = QString::number(i + 1);
        if (seg.width() > fm.horizontalAdvance(n) + 4) {
            p.setPen(c.lightnessF() > 0.55 ? Qt::black : Qt::white);
            p.drawText(seg, Qt::AlignCenter, n);
        }
        from = range_.ends[i];
    }
    p.setPen(QPen(text, 1));
    p.setBrush(Qt::NoBrush);
    p.drawRect(QRectF(r).adjusted(0.5, 0.5, -0.5, -0.5));

    // Split handles with their distances above, in two rows where neighbours would overlap.
    const bool draggable = manual();
    std::vector<QRect> placed;
    for (size_t i = 0; i + 1 < range_.ends.size(); ++i) {
        const double x = xOf(range_.ends[i]);
        p.setPen(QPen(text, int(i) == dragging_ ? 3 : 2));
        p.drawLine(QPointF(x, r.top() - kGrip), QPointF(x, r.bottom() + 3));
        QPolygonF grip;
        grip << QPointF(x - kGrip, r.top() - kGrip - 1) << QPointF(x + kGrip, r.top() - kGrip - 1)
             << QPointF(x, r.top());
        p.setPen(QPen(text, 1));
        p.setBrush(draggable ? QBrush(text) : QBrush(palette().color(QPalette::Window)));
        p.drawPolygon(grip);
        p.setBrush(Qt::NoBrush);

        const QString label = splitText(range_.ends[i]);
        const int w = fm.horizontalAdvance(label);
        const int left = std::clamp(int(std::lround(x)) - w / 2, 0, std::max(0, width() - w));
        QRect box(left, r.top() - kGrip - 2 - fh, w, fh);
        if (overlaps(placed, box, 4)) box.translate(0, -fh);
        placed.push_back(box);
        p.setPen(text);
        p.drawText(box, Qt::AlignCenter, label);
    }

    // The axis: the exact near and far distances at the ends, round distances between.
    const int tickTop = r.bottom() + 1, labelTop = r.bottom() + 6;
    p.setPen(text);
    std::vector<QRect> axis;
    auto endLabel = [&](double d, bool atLeft) {
        const QString t = axisText(d);
        const int w = fm.horizontalAdvance(t);
        const int x = int(std::lround(xOf(d)));
        const QRect box(atLeft ? std::max(0, x - 2) : std::min(width() - w, x - w + 2), labelTop, w, fh);
        p.drawLine(x, tickTop, x, tickTop + 4);
        p.drawText(box, Qt::AlignCenter, t);
        axis.push_back(box);
    };
    endLabel(range_.nearDistance, true);
    endLabel(range_.farDistance, false);
    const double span = range_.farDistance - range_.nearDistance;
    if (span > 0.0) {
        const double step = tickStep(span, std::max(2, r.width() / 80));
        for (double d = std::ceil(range_.nearDistance / step) * step; d < range_.farDistance; d += step) {
            const int x = int(std::lround(xOf(d)));
            p.drawLine(x, tickTop, x, tickTop + 3);
            const QString t = axisText(d);
            const int w = fm.horizontalAdvance(t);
            const QRect box(x - w / 2, labelTop, w, fh);
            if (overlaps(axis, box, 6)) continue;
            p.drawText(box, Qt::AlignCenter, t);
            axis.push_back(box);
        }
    }
}

void CascadeSplitChart::mousePressEvent(QMouseEvent* e) {
    if (e->button() != Qt::LeftButton || !manual()) return QWidget::mousePressEvent(e);
    const int i = handleAt(e->position().x());
    if (i < 0) return QWidget::mousePressEvent(e);
    dragging_ = i;
    dragSplits_ = *doc_->project().scene.shadows.splits;
    e->accept();
    update();
}

void CascadeSplitChart::mouseMoveEvent(QMouseEvent* e) {
    if (dragging_ < 0) {
        setCursor(manual() && handleAt(e->position().x()) >= 0 ? Qt::SizeHorCursor : Qt::ArrowCursor);
        return QWidget::mouseMoveEvent(e);
    }
    const ShadowSettings& s = doc_->project().scene.shadows;
    const size_t i = size_t(dragging_);
    // Between the neighbours with a gap (whole metres, or a sliver of a short range), inside the
    // drawn range and below the shadow distance: the splits stay valid throughout.
    const double gap = std::max(std::min(1.0, 0.01 * (range_.farDistance - range_.nearDistance)), 1e-3);
    double hi = range_.farDistance;
    if (s.maxDistance) hi = std::min(hi, *s.maxDistance);
    if (i + 1 < dragSplits_.size()) hi = std::min(hi, dragSplits_[i + 1]);
    hi -= gap;
    const double lo = std::max(i > 0 ? dragSplits_[i - 1] + gap : gap, range_.nearDistance);
    if (lo <= hi) {
        double d = std::clamp(distanceAt(e->position().x()), lo, hi);
        if (const double whole = std::round(d); whole >= lo && whole <= hi) d = whole;
        dragSplits_[i] = d;
        refresh();
    }
    e->accept();
}

void CascadeSplitChart::mouseReleaseEvent(QMouseEvent* e) {
    if (dragging_ < 0 || e->button() != Qt::LeftButton) return QWidget::mouseReleaseEvent(e);
    dragging_ = -1;
    const std::vector<double> splits = dragSplits_;
    QString error;
    if (splits != *doc_->project().scene.shadows.splits &&
        !doc_->setParameter("shadows.splits", nlohmann::json(splits), &error))
        emit rejected(error);
    refresh();
    e->accept();
}

}  // namespace terralux
