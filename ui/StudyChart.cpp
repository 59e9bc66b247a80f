#include "StudyChart.h"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <map>
#include <memory>

#include <QApplication>
#include <QBuffer>
#include <QGraphicsScene>
#include <QImage>
#include <QPainter>
#include <QtCharts/QChart>
#include <QtCharts/QLegendMarker>
#include <QtCharts/QLineSeries>
#include <QtCharts/QLogValueAxis>
#include <QtCharts/QScatterSeries>

#include "AtomicFile.h"

namespace terralux {
namespace {

// Log axes cannot show 0: an exact answer is drawn at this error.
constexpr double kErrorFloor = 1e-4;
constexpr double kTimeFloor = 1e-4;

QPointF at(const StudyPoint& p) {
    return {std::max(p.seconds, kTimeFloor), std::max(p.errorP95, kErrorFloor)};
}

QString seriesName(const std::string& knob) {
    static const std::map<std::string, QString> names = {
        {"quality", "quality preset"}, {"rays", "rays"}, {"bounces", "bounces"},
        {"spacing", "probe spacing"}, {"tolerance", "adaptive tolerance"},
        {"placement_quality", "dense placements at draft / high"},
        {"error_map", "error-map resolution (its p95's error)"},
        {"ao_directions", "AO directions (AO error)"},
        {"lpv_quality", "LPV quality (LPV error)"}, {"lpv_cascades", "LPV cascades (LPV error)"},
        {"reflection_resolution", "reflection cube size (reflection error)"},
        {"reflection_rays", "reflection rays per texel (reflection error)"},
        {"reflection_encoding", "reflection encoding (reflection error)"},
        {"shadow_cascades", "shadow cascades (shadow error)"},
        {"shadow_resolution", "shadow map size (shadow error)"},
        {"shadow_filter", "shadow filter (shadow error)"}};
    auto it = names.find(knob);
    return it != names.end() ? it->second : QString::fromStdString(knob);
}

// A qualitative palette (Tableau 10): the chart theme's five colours repeat past five series.
const QColor kPalette[] = {QColor(78, 121, 167), QColor(242, 142, 43), QColor(89, 161, 79), QColor(225, 87, 89),
                           QColor(118, 183, 178), QColor(237, 201, 72), QColor(176, 122, 161), QColor(255, 157, 167),
                           QColor(156, 117, 95), QColor(186, 176, 172)};

// Whole decades around [lo, hi], so the log axes read as powers of ten.
void decades(double lo, double hi, double& a, double& b) {
    a = std::pow(10.0, std::floor(std::log10(lo)));
    b = std::pow(10.0, std::ceil(std::log10(hi)));
    if (!(b > a)) b = a * 10.0;
}

}  // namespace

StudyChart makeStudyChart(const StudyResult& r) {
    StudyChart out;
    auto* chart = new QChart();
    out.chart = chart;
    chart->setTitle(QString("Error against time: %1 on %2 (p95; %3 reference points)")
                        .arg(QString::fromStdString(r.volume), QString::fromStdString(r.terrain))
                        .arg(r.reference.points));
    chart->legend()->setAlignment(Qt::AlignRight);
    auto* x = new QLogValueAxis();
    x->setTitleText("time (s)");
    x->setLabelFormat("%g");
    x->setBase(10.0);
    x->setMinorTickCount(-1);
    auto* y = new QLogValueAxis();
    y->setTitleText("error, 95th percentile");
    y->setLabelFormat("%g");
    y->setBase(10.0);
    y->setMinorTickCount(-1);
    chart->addAxis(x, Qt::AlignBottom);
    chart->addAxis(y, Qt::AlignLeft);

    double tLo = INFINITY, tHi = 0, eLo = INFINITY, eHi = 0;
    auto extend = [&](QPointF p) {
        tLo = std::min(tLo, p.x()), tHi = std::max(tHi, p.x());
        eLo = std::min(eLo, p.y()), eHi = std::max(eHi, p.y());
    };
    auto attach = [&](QXYSeries* s) {
        chart->addSeries(s);
        s->attachAxis(x);
        s->attachAxis(y);
    };

    // The probe settings every knob shares: the current point joins each probe knob's line, so a
    // series reads as "from here, turning this knob".
    const StudyPoint* current = nullptr;
    for (const StudyPoint& p : r.points)
        if (p.knob == "current") current = &p;
    std::vector<std::string> knobs;
    for (const StudyPoint& p : r.points)
        if (p.knob != "current" && std::find(knobs.begin(), knobs.end(), p.knob) == knobs.end()) knobs.push_back(p.knob);
    for (const std::string& knob : knobs) {
        std::vector<size_t> idx;
        for (size_t i = 0; i < r.points.size(); ++i)
            if (r.points[i].knob == knob) idx.push_back(i);
        const StudyMetric metric = r.points[idx.front()].metric;
        // Combinations of two knobs are not a line through the current point: drawn as points.
        const bool combined = knob == "placement_quality";
        if (metric == StudyMetric::Irradiance && current && !combined) idx.push_back(size_t(current - r.points.data()));
        std::sort(idx.begin(), idx.end(), [&](size_t a, size_t b) { return r.points[a].seconds < r.points[b].seconds; });
        if (combined) {
            auto* s = new QScatterSeries();
            s->setName(seriesName(knob));
            s->setMarkerSize(9.0);
            for (size_t i : idx) {
                s->append(at(r.points[i]));
                extend(at(r.points[i]));
            }
            attach(s);
            s->setColor(kPalette[out.series.size() % std::size(kPalette)]);
            s->setBorderColor(Qt::transparent);
            out.series.emplace_back(s, idx);
            continue;
        }
        auto* s = new QLineSeries();
        s->setName(seriesName(knob));
        s->setPointsVisible(true);
        for (size_t i : idx) {
            s->append(at(r.points[i]));
            extend(at(r.points[i]));
        }
        attach(s);
        QPen pen(kPalette[(out.series.size()) % std::size(kPalette)]);
        pen.setWidthF(2.0);
        if (metric != StudyMetric::Irradiance) pen.setStyle(Qt::DotLine);
        s->setPen(pen);
        out.series.emplace_back(s, idx);
    }

    std::vector<size_t> front;
    for (size_t i = 0; i < r.points.size(); ++i)
        if (r.points[i].pareto) front.push_back(i);
    std::sort(front.begin(), front.end(), [&](size_t a, size_t b) { return r.points[a].seconds < r.points[b].seconds; });
    if (!front.empty()) {
        auto* s = new QLineSeries();
        s->setName("Pareto front (probe settings)");
        QPen pen(QColor(30, 30, 30));
        pen.setWidthF(3.0);
        pen.setStyle(Qt::DashLine);
        s->setPen(pen);
        for (size_t i : front) s->append(at(r.points[i]));
        attach(s);
        out.series.emplace_back(s, front);
    }
    std::vector<size_t> marked;
    for (size_t i = 0; i < r.points.size(); ++i)
        if (r.points[i].current) marked.push_back(i);
    if (!marked.empty()) {
        auto* s = new QScatterSeries();
        s->setName("current settings");
        s->setMarkerShape(QScatterSeries::MarkerShapeStar);
        s->setMarkerSize(22.0);
        s->setColor(QColor(220, 30, 30));
        s->setBorderColor(QColor(90, 0, 0));
        for (size_t i : marked) {
            s->append(at(r.points[i]));
            extend(at(r.points[i]));
        }
        attach(s);
        out.series.emplace_back(s, marked);
    }
    if (tHi > 0.0) {
        double a, b;
        decades(tLo, tHi, a, b);
        x->setRange(a, b);
        decades(eLo, eHi, a, b);
        y->setRange(a, b);
    }
    return out;
}

void writeStudyPlotPng(const StudyResult& result, const std::filesystem::path& png, int width, int height) {
    // The command line has no application object; the chart's graphics items need one, for as
    // long as they are drawn (one outliving main's return would be torn down after Qt's own state).
    int argc = 1;
    char name[] = "terralux";
    char* argv[] = {name, nullptr};
    std::unique_ptr<QApplication> own;
    QtMessageHandler previous = nullptr;
    if (!qApp) {
        qputenv("QT_QPA_PLATFORM", "offscreen");
        // The offscreen platform's notes (no XDG runtime folder) are not the user's concern.
        previous = qInstallMessageHandler([](QtMsgType type, const QMessageLogContext&, const QString& msg) {
            if (type == QtCriticalMsg || type == QtFatalMsg) std::fprintf(stderr, "terralux: %s\n", qPrintable(msg));
        });
        own = std::make_unique<QApplication>(argc, argv);
    }
    QImage image(width, height, QImage::Format_ARGB32_Premultiplied);
    image.fill(Qt::white);
    {
        QGraphicsScene scene;
        StudyChart c = makeStudyChart(result);
        scene.addItem(c.chart);  // the scene owns it
        c.chart->setGeometry(0, 0, width, height);
        QPainter painter(&image);
        painter.setRenderHint(QPainter::Antialiasing);
        scene.render(&painter, QRectF(0, 0, width, height), QRectF(0, 0, width, height));
    }
    QByteArray bytes;
    QBuffer buffer(&bytes);
    buffer.open(QIODevice::WriteOnly);
    if (!image.save(&buffer, "PNG")) throw FileWriteError(png.string() + ": the plot could not be encoded as PNG");
    own.reset();
    if (previous) qInstallMessageHandler(previous);
    writeFileAtomically(png, std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(bytes.constData()), size_t(bytes.size())));
}

}  // namespace terralux
