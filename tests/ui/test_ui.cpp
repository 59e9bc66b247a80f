// The authoring window driven by Qt Test through objectNames, under Xvfb (ctest wraps it in
// xvfb-run); skips, saying why, without a display or a Vulkan device.
#include <cmath>
#include <functional>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>

#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QColorDialog>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QDockWidget>
#include <QElapsedTimer>
#include <QFileDialog>
#include <QFormLayout>
#include <QStatusBar>
#include <QTabBar>
#include <QTableWidget>
#include <QLabel>
#include <QLineEdit>
#include <QMessageBox>
#include <QPointer>
#include <QProgressBar>
#include <QPushButton>
#include <QScrollArea>
#include <QScrollBar>
#include <QListWidget>
#include <QSlider>
#include <QToolBar>
#include <QScreen>
#include <QSignalSpy>
#include <QSpinBox>
#include <QTimer>
#include <QUndoStack>
#include <QWheelEvent>
#include <QtTest>
#include <QtCharts/QXYSeries>

#include "CascadeSplitChart.h"
#include "ImageCompare.h"
#include "ImageFile.h"
#include "LpvConsoleVariables.h"
#include "LpvPanel.h"
#include "MainWindow.h"
#include "ViewportGizmos.h"
#include "ProbeInspector.h"
#include "ReflectionPanel.h"
#include "TradeoffPanel.h"
#include "bake/ReflectionBake.h"
#include "ParameterPanels.h"
#include "ParameterTable.h"
#include "bake/ProbePlacement.h"
#include "BakeJob.h"
#include "ProjectRenderer.h"
#include "SceneLighting.h"
#include "TerrainLoading.h"
#include "scene/DebugViews.h"
#include "water/Water.h"
#include "scene/ShadowCascades.h"

using namespace terralux;
namespace fs = std::filesystem;

namespace {

const fs::path kOut = fs::path(TERRALUX_BINARY_DIR) / "ui_out";

std::string fileBytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

// Whether the viewport, within twenty tries, goes 300 ms without presenting a frame and with none
// submitted, asked for or due: frames asked for before may still land (slow under load; a worker's
// result, a horizon map or the terrain's levels, asks for one more), but a viewport that keeps
// drawing never goes quiet.
bool settlesQuiet(ViewportWindow* viewport) {
    for (int attempt = 0; attempt < 20; ++attempt) {
        QSignalSpy frames(viewport, &ViewportWindow::frameRendered);
        QTest::qWait(300);
        if (frames.count() == 0 && !viewport->drawing()) return true;
    }
    return false;
}

// The UI thread's longest stall while it lives: a timer ticking every 5 ms, and the longest gap
// between its ticks.
class Watchdog {
public:
    Watchdog() {
        clock_.start();
        timer_.setInterval(5);
        QObject::connect(&timer_, &QTimer::timeout, [this] {
            worst_ = std::max(worst_, clock_.elapsed() - last_);
            last_ = clock_.elapsed();
        });
        timer_.start();
    }
    qint64 worst() const { return worst_; }

private:
    QElapsedTimer clock_;
    QTimer timer_;
    qint64 last_ = 0, worst_ = 0;
};

// Waits for the next draft preview or bake to reach the viewport.
bool waitForProbes(MainWindow& w, const QString& source, int ms = 20000) {
    return QTest::qWaitFor([&] { return w.probeSource() == source; }, ms);
}

// Answers modal dialogs as they open (they come from exec(), so poll): each handler gets the
// active modal widget and returns true when it dealt with it; handlers run once, in order.
class DialogAnswers {
public:
    explicit DialogAnswers(std::vector<std::function<bool(QWidget*)>> handlers) : handlers_(std::move(handlers)) {
        timer_.setInterval(20);
        QObject::connect(&timer_, &QTimer::timeout, [this] {
            QWidget* w = QApplication::activeModalWidget();
            if (w && next_ < handlers_.size() && w != last_ && handlers_[next_](w)) {
                last_ = w;
                ++next_;
            }
        });
        timer_.start();
    }
    bool done() const { return next_ == handlers_.size(); }

private:
    std::vector<std::function<bool(QWidget*)>> handlers_;
    size_t next_ = 0;
    QPointer<QWidget> last_;  // a new dialog may reuse a closed one's address
    QTimer timer_;
};

// A handler that picks `path` in the file dialog named `name`.
std::function<bool(QWidget*)> pickFile(const QString& name, const fs::path& path) {
    return [name, path](QWidget* w) {
        auto* d = qobject_cast<QFileDialog*>(w);
        if (!d || d->objectName() != name) return false;
        d->selectFile(QString::fromStdString(path.string()));
        // The dialog fills its name field from its file model, asynchronously: type the path too.
        if (auto* name = d->findChild<QLineEdit*>("fileNameEdit")) name->setText(QString::fromStdString(path.string()));
        static_cast<QDialog*>(d)->accept();  // QFileDialog::accept, as the Save button
        return true;
    };
}

// The widget a form row shows (a spin box's row holds its slider; a list row its spin boxes).
QWidget* rowOf(QWidget* editor) {
    while (editor->parentWidget() && !qobject_cast<ParameterForm*>(editor->parentWidget())) editor = editor->parentWidget();
    return editor;
}

// Cheap bakes for tests that only need one to land.
void quickBakeSettings(ProjectDocument& doc) {
    QString error;
    QVERIFY(doc.setParameter("bake.quality", "draft", &error));
    QVERIFY(doc.setParameter("bake.error_map_resolution", 0, &error));  // the preview's too
    QVERIFY(doc.setParameter("bake.bounces", 0, &error));
    QVERIFY(doc.setParameter("bake.rays", 16, &error));
}

}  // namespace

class UiTest : public QObject {
    Q_OBJECT
    std::unique_ptr<MainWindow> w_;
    QString skip_;

    // Imports `dem` (its terrain at `latitude`), lets its first frames and `whileShown` settle,
    // undoes back to the terrain before, and holds the longest stall of the UI thread over all of
    // it to 100 ms; both renderers are made on workers.
    void importThenUndoWithoutStalls(const fs::path& dem, double latitude, const char* what,
                                     const std::function<void(ProjectRenderer&)>& whileShown = {}) {
        ProjectDocument& doc = *w_->document();
        ViewportWindow* v = w_->viewport();
        v->renderNow();
        QVERIFY(settlesQuiet(v));
        const double before = doc.terrain().heightfield.geo.latitudeDeg;
        const unsigned made = w_->renderersMadeOnWorkers(), tornDown = w_->renderersTornDownOnWorkers();
        Watchdog watchdog;
        QVERIFY(w_->importDemFile(QString::fromStdString(dem.string())));
        auto shows = [&](double at) {
            return !doc.terrainLoading() && v->renderer() &&
                   std::abs(v->renderer()->heightfield().geo.latitudeDeg - at) < 0.01;
        };
        QTRY_VERIFY_WITH_TIMEOUT(shows(doc.terrain().heightfield.geo.latitudeDeg) &&
                                     std::abs(doc.terrain().heightfield.geo.latitudeDeg - latitude) < 0.5,
                                 60000);
        // Its first frame waited for its own meter reading (the project meters by default) and
        // was drawn.
        QTRY_VERIFY_WITH_TIMEOUT(!std::isnan(v->renderer()->meteredEv100()), 20000);
        if (whileShown) whileShown(*v->renderer());
        if (QTest::currentTestFailed()) return;
        QVERIFY(settlesQuiet(v));
        QVERIFY(!v->renderer()->deferredFrame());
        doc.undoStack()->undo();
        QTRY_VERIFY_WITH_TIMEOUT(shows(before), 30000);
        QTRY_VERIFY_WITH_TIMEOUT(!std::isnan(v->renderer()->meteredEv100()), 10000);
        QVERIFY(settlesQuiet(v));
        QVERIFY(!v->renderer()->deferredFrame());
        const qint64 worst = watchdog.worst();
        qInfo() << what << "import and undo: longest UI stall" << worst << "ms";
        QVERIFY2(worst <= 100, qPrintable(QString("the UI thread stalled %1 ms").arg(worst)));
        QCOMPARE(w_->renderersMadeOnWorkers(), made + 2);
        // The sample's renderer and the imported terrain's were torn down on workers (a
        // 16 384² grid's held the UI thread 100 ms).
        QTRY_COMPARE(w_->renderersTornDownOnWorkers(), tornDown + 2);
    }

private slots:
    void initTestCase() {
        if (QGuiApplication::platformName() == "offscreen" || QGuiApplication::platformName() == "minimal")
            skip_ = "no display (platform " + QGuiApplication::platformName() + ")";
        fs::remove_all(kOut);
        fs::create_directories(kOut);
        qputenv("TERRALUX_AUTOSAVE_DIR", QByteArray::fromStdString((kOut / "autosave").string()));
    }
    void init() {
        if (!skip_.isEmpty()) QSKIP(qPrintable(skip_));
        try {
            w_ = std::make_unique<MainWindow>();
        } catch (const vk::VulkanUnavailable& e) {
            QSKIP(e.what());
        }
        w_->resize(1280, 800);
        w_->show();
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
        QVERIFY(waitForProbes(*w_, "draft preview"));
        QString error;
        QVERIFY(w_->document()->setParameter("export.out_dir", (kOut / "bake").string(), &error));
    }
    void cleanup() {
        if (w_) w_->document()->undoStack()->setClean();
        w_.reset();
    }

    // The docks stand in three tab groups of four, each tab's whole label on show at the test's
    // 1280 x 800 window: none hides behind the scroll arrows (eight tabs in one group did).
    void everyDockTabShowsWithoutScrolling() {
        int groups = 0;
        QStringList titles;
        for (QTabBar* bar : w_->findChildren<QTabBar*>()) {
            if (bar->parentWidget() != w_.get() || bar->count() < 2 || !bar->isVisible()) continue;
            ++groups;
            for (int i = 0; i < bar->count(); ++i) {
                titles << bar->tabText(i);
                const QRect r = bar->tabRect(i);
                QVERIFY2(r.left() >= 0 && r.right() < bar->width(),
                         qPrintable(bar->tabText(i) + " lies outside its tab bar"));
            }
        }
        QCOMPARE(groups, 3);
        QCOMPARE(titles.size(), 12);
        for (const char* t : {"Water", "LPV", "Trade-off", "Atmosphere"}) QVERIFY(titles.contains(t));
    }

    // A project whose bake is current shows the bake and bakes no preview: when it is opened, and
    // again once an edit that made the bake stale is undone.
    void aCurrentBakeStaysShownOverThePreview() {
        ProjectDocument* doc = w_->document();
        quickBakeSettings(*doc);
        w_->startBake();
        QVERIFY(QTest::qWaitFor([&] { return !w_->bakes()->running() && w_->probeSource() == "last bake"; }, 60000));
        const QString file = QString::fromStdString((kOut / "current_bake.terralux.json").string());
        QString error;
        QVERIFY2(doc->saveAs(file, &error), qPrintable(error));
        const unsigned previews = w_->previewsStarted();
        QVERIFY2(doc->open(file, &error), qPrintable(error));
        QVERIFY(waitForProbes(*w_, "last bake"));
        QTest::qWait(1500);
        QCOMPARE(w_->probeSource(), QString("last bake"));
        QCOMPARE(w_->previewsStarted(), previews);
        // An edit the bake reads: a draft preview; undone: the bake again; redone: the preview.
        QVERIFY(doc->setParameter("sun.elevation_deg", 20.0, &error));
        QVERIFY(waitForProbes(*w_, "draft preview"));
        doc->undoStack()->undo();
        QVERIFY(waitForProbes(*w_, "last bake"));
        doc->undoStack()->redo();
        QVERIFY(waitForProbes(*w_, "draft preview"));
    }

    // The fog colour left to the sky says so on its button, and the picker starts from the colour
    // it resolves to (the uniform sky's mean colour), not from nothing; the luminance, still left
    // to the sky, keeps the fog's light as it was.
    void fogColourLeftToTheSkySaysSo() {
        auto* dock = w_->findChild<QDockWidget*>("dock.atmosphere");
        dock->raise();
        ProjectDocument* doc = w_->document();
        QString error;
        QVERIFY(doc->setParameter("fog.enabled", true, &error));
        QVERIFY(doc->value("fog.color").is_null());
        auto* button = dock->findChild<QPushButton*>("param.fog.color");
        QVERIFY(button);
        QCOMPARE(button->text(), QString("auto: the sky's mean colour"));
        QVERIFY(doc->value("fog.luminance").is_null());
        const glm::vec3 sky = doc->project().scene.sky.color;
        QColor started;
        QTimer::singleShot(200, [&] {
            auto* dialog = qobject_cast<QColorDialog*>(QApplication::activeModalWidget());
            if (!dialog) return;
            started = dialog->currentColor();
            dialog->accept();
        });
        button->click();
        QVERIFY(started.isValid());
        // The sky's colour, as the dialog's 8-bit channels hold it.
        QVERIFY(std::abs(started.redF() - sky.x) < 0.01 && std::abs(started.blueF() - sky.z) < 0.01);
        const auto& set = doc->project().scene.fog.color;
        QVERIFY(set.has_value());
        QVERIFY(std::abs(set->x - sky.x) < 0.01f && std::abs(set->z - sky.z) < 0.01f);
        QVERIFY(button->text().startsWith("0.6"));
    }

    void startsWithTheSampleAndEditsAreUndoable() {
        QCOMPARE(w_->document()->terrain().heightfield.width(), 256);
        // Probe irradiance shows a grid change most directly.
        auto* selector = w_->findChild<QComboBox*>("viewport.debugView");
        selector->setCurrentIndex(selector->findData(kViewProbeIrradiance));
        w_->viewport()->renderNow();
        const RenderedImage before = w_->viewport()->grabImage();
        auto* nx = w_->findChild<QSpinBox*>("param.volume.grid_dims.0");
        QVERIFY(nx);
        QCOMPARE(nx->value(), 8);
        nx->setValue(2);
        QCOMPARE(w_->document()->project().scene.probeVolumes[0].gridDims[0], 2);
        QVERIFY(QTest::qWaitFor([&] {
            // A grid change moves probe light locally: a clear local change and a non-zero mean.
            const auto d = test::compareImages(w_->viewport()->grabImage().rgba, before.rgba, before.width, before.height);
            return d.maxAbs > 6.0 / 255.0 && d.meanAbs > 0.1 / 255.0;
        }, 20000));
        w_->findChild<QAction*>("action.undo")->trigger();
        QCOMPARE(nx->value(), 8);
        QCOMPARE(w_->document()->project().scene.probeVolumes[0].gridDims[0], 8);
        QVERIFY(QTest::qWaitFor([&] {
            return test::compareImages(w_->viewport()->grabImage().rgba, before.rgba, before.width, before.height).maxAbs <= 1.0 / 255.0;
        }, 20000));
    }

    void probePositionOverlayFollowsTheGrid() {
        auto* overlay = w_->findChild<QCheckBox*>("viewport.probePositions");
        QVERIFY(overlay);
        w_->viewport()->renderNow();
        const RenderedImage plain = w_->viewport()->grabImage();
        overlay->setChecked(true);
        w_->viewport()->renderNow();
        const RenderedImage marked = w_->viewport()->grabImage();
        // Yellow markers: pixels whose blue channel falls far below red.
        auto yellow = [](const RenderedImage& img) {
            size_t n = 0;
            for (size_t i = 0; i < size_t(img.width) * img.height; ++i)
                n += img.rgba[i * 4] > 0.9f && img.rgba[i * 4 + 2] < 0.3f;
            return n;
        };
        QCOMPARE(yellow(plain), size_t(0));
        const size_t at64 = yellow(marked);
        QVERIFY(at64 > 64 * 9);
        QString error;
        QVERIFY(w_->document()->setParameter("probe_volumes[0].grid_dims", nlohmann::json{2, 2}, &error));
        w_->viewport()->renderNow();
        const size_t at4 = yellow(w_->viewport()->grabImage());
        QVERIFY2(at4 < at64 / 8 && at4 > 0, qPrintable(QString("%1 vs %2").arg(at4).arg(at64)));
    }

    void adaptivePlacementThroughThePanel() {
        auto* placement = w_->findChild<QComboBox*>("param.volume.placement");
        QVERIFY(placement);
        placement->setCurrentText("adaptive");
        QCOMPARE(w_->document()->project().scene.probeVolumes[0].placement, ProbePlacement::Adaptive);
        auto* tolerance = w_->findChild<QDoubleSpinBox*>("param.volume.adaptive.tolerance");
        QVERIFY(tolerance);
        tolerance->setValue(0.05);
        QCOMPARE(w_->document()->value("probe_volumes[0].adaptive.tolerance").get<double>(), 0.05);
        QVERIFY(w_->findChild<QLabel*>("bake.estimate")->text().contains("probes"));
        w_->findChild<QAction*>("action.undo")->trigger();
        w_->findChild<QAction*>("action.undo")->trigger();
        QCOMPARE(placement->currentText(), QString("terrain"));
    }

    void leafOverlayAndErrorMapSetting() {
        auto* leaves = w_->findChild<QCheckBox*>("viewport.leaves");
        QVERIFY(leaves);
        auto* placement = w_->findChild<QComboBox*>("param.volume.placement");
        placement->setCurrentText("adaptive");
        w_->viewport()->renderNow();
        const RenderedImage plain = w_->viewport()->grabImage();
        leaves->setChecked(true);
        w_->viewport()->renderNow();
        const RenderedImage lines = w_->viewport()->grabImage();
        const auto d = test::compareImages(plain.rgba, lines.rgba, plain.width, plain.height);
        QVERIFY2(d.maxAbs > 0.2, qPrintable(QString("leaf overlay changed the image by %1").arg(d.maxAbs)));
        leaves->setChecked(false);
        w_->findChild<QAction*>("action.undo")->trigger();
        QCOMPARE(placement->currentText(), QString("terrain"));

        // The error map's size is a bake setting with its own row, and the estimate counts it.
        auto* points = w_->findChild<QSpinBox*>("param.bake.error_map_resolution");
        QVERIFY(points);
        QCOMPARE(points->value(), 64);
        auto* estimate = w_->findChild<QLabel*>("bake.estimate");
        QVERIFY2(estimate->text().contains("4096 error-map points"), qPrintable(estimate->text()));
        points->setValue(0);
        QCOMPARE(w_->document()->project().scene.bake.errorMapResolution, 0);
        QVERIFY2(estimate->text().contains(" 0 error-map points"), qPrintable(estimate->text()));
        w_->findChild<QAction*>("action.undo")->trigger();
        QCOMPARE(points->value(), 64);
    }

    // An orbit drag never makes the UI thread wait: frames are presented once the device has
    // drawn them (Mesa's software presentation waited inside vkQueuePresentKHR, 55-360 ms a
    // frame), and a metered exposure, a frame of its own drawn and read back while the UI thread
    // waits (170-260 ms at 128 pixels on lavapipe), is not taken by the frames of a change, drawn
    // below full resolution: they keep the exposure last metered, and the full-resolution frame
    // that follows meters once. A watchdog ticking every 5 ms measures the UI thread's longest
    // stall over the drag.
    void framesOfAChangeKeepTheExposureAndTheFullFrameMeters() {
        QString error;
        QVERIFY(w_->document()->setParameter("camera.exposure_mode", "average", &error));
        ViewportWindow* v = w_->viewport();
        ProjectRenderer* r = v->renderer();
        QVERIFY(r);
        v->setFrameBudget(1.0);  // no frame meets it: every frame of a change is drawn small
        v->renderNow();
        QVERIFY(settlesQuiet(v));
        QCOMPARE(v->presentedScale(), 1.0);
        const size_t before = r->meterings();
        const double metered = r->meteredEv100();
        QVERIFY(std::isfinite(metered));

        QSignalSpy frames(v, &ViewportWindow::frameRendered);
        Watchdog watchdog;
        // An orbit drag toward the ground: a darker, different frame the exposure would follow.
        const QPoint c(v->width() / 2, v->height() / 2);
        QTest::mousePress(v, Qt::LeftButton, {}, c);
        double smallest = 1.0;
        for (int i = 1; i <= 24; ++i) {
            const QPointF at(c + QPoint(3 * i, -4 * i));
            QMouseEvent move(QEvent::MouseMove, at, v->mapToGlobal(at), Qt::NoButton, Qt::LeftButton, {});
            QCoreApplication::sendEvent(v, &move);
            QTest::qWait(50);
            smallest = std::min(smallest, v->presentedScale());
        }
        const qint64 dragStall = watchdog.worst();
        const int dragFrames = int(frames.count());
        const size_t duringDrag = r->meterings() - before;
        QTest::mouseRelease(v, Qt::LeftButton, {}, c + QPoint(72, -96));
        qInfo() << "drag:" << dragFrames << "frames, longest UI stall" << dragStall << "ms, meterings" << duringDrag;
        QVERIFY2(dragFrames >= 1, qPrintable(QString::number(dragFrames)));
        // The watchdog: the UI thread answered within 50 ms throughout the drag.
        QVERIFY2(dragStall <= 50, qPrintable(QString("the UI thread stalled %1 ms").arg(dragStall)));
        QVERIFY(smallest < 1.0);
        QCOMPARE(duringDrag, size_t(0));
        QCOMPARE(r->meteredEv100(), metered);
        // The full-resolution frame meters the camera the drag left.
        QTRY_VERIFY_WITH_TIMEOUT(r->meterings() == before + 1, 10000);
        QTRY_VERIFY_WITH_TIMEOUT(!r->exposureAdapting(), 15000);
        QVERIFY(settlesQuiet(v));
        QCOMPARE(v->presentedScale(), 1.0);
        QCOMPARE(r->meterings(), before + 1);
        QVERIFY2(std::abs(r->meteredEv100() - metered) > 1e-3,
                 qPrintable(QString("metered %1 before and after the drag").arg(metered)));
    }

    // Edits of the sun through its spin box never make the UI thread wait: the renderer takes the
    // new project without waiting for the frames in flight (the resources it replaces are
    // retired, buffers on a CPU device are written in place), and the preview's probes land the
    // same way. Each edit reaches the screen. With a metered exposure the meter's frame is drawn
    // behind the viewport's and its reading taken a frame later: nothing waits for it either.
    void sunEditsNeverHoldTheUiThread_data() {
        QTest::addColumn<QString>("mode");
        QTest::newRow("manual") << "manual";
        QTest::newRow("histogram") << "histogram";
    }

    void sunEditsNeverHoldTheUiThread() {
        QFETCH(QString, mode);
        QString error;
        QVERIFY(w_->document()->setParameter("camera.exposure_mode", mode.toStdString(), &error));
        ViewportWindow* v = w_->viewport();
        ProjectRenderer* r = v->renderer();
        QVERIFY(r);
        v->renderNow();
        QTRY_VERIFY_WITH_TIMEOUT(!r->exposureAdapting(), 15000);
        QVERIFY(settlesQuiet(v));
        auto* elevation = w_->findChild<QDoubleSpinBox*>("param.sun.elevation_deg");
        QVERIFY(elevation);
        const size_t meterings = r->meterings();
        Watchdog watchdog;
        const QString before = w_->probeSource();
        for (int i = 0; i < 5; ++i) {
            QSignalSpy frames(v, &ViewportWindow::frameRendered);
            elevation->setValue(elevation->value() + 2.0);
            QTRY_VERIFY_WITH_TIMEOUT(frames.count() >= 1, 5000);
            QTest::qWait(400);  // the preview bakes and lands, and the full frame may begin
        }
        QTRY_VERIFY_WITH_TIMEOUT(!r->exposureAdapting(), 15000);
        QVERIFY(settlesQuiet(v));
        const qint64 worst = watchdog.worst();
        qInfo() << mode << "exposure, sun edits: longest UI stall" << worst << "ms, meterings" << r->meterings() - meterings;
        QVERIFY2(worst <= 50, qPrintable(QString("the UI thread stalled %1 ms").arg(worst)));
        QCOMPARE(before, QString("draft preview"));
        QCOMPARE(w_->probeSource(), QString("draft preview"));
        if (mode == "manual") {
            QCOMPARE(r->meterings(), meterings);
        } else {
            // Every edit changed the frame: the meter read the new ones, and the eye settled on
            // the last reading.
            QVERIFY(r->meterings() > meterings);
            QVERIFY(std::abs(r->shownEv100() - r->meteredEv100()) <= 0.02);
        }
    }

    // A sky image or an albedo map set while frames are in flight (the water's waves keep them
    // coming) is copied in by the next frame, and the old one goes once those frames are done:
    // uploading it with a submission of its own and waiting for the device before freeing the old
    // one held the UI thread 0.1-0.3 s a sky edit on lavapipe. A physical sky's image changes with
    // the sun (both suns' skies are made before the watch: the first is a pass over the sky).
    void skyAndAlbedoEditsNeverHoldTheUiThread() {
        ProjectDocument* doc = w_->document();
        QString error;
        const nlohmann::json water = doc->value("water.enabled"), sky = doc->value("sky.mode"),
                             elevation = doc->value("sun.elevation_deg"), albedo = doc->value("terrain.albedo_mode");
        QVERIFY(doc->setParameter("water.enabled", true, &error));
        QVERIFY(doc->setParameter("sky.mode", "physical", &error));
        for (double e : {30.0, 40.0}) {
            QVERIFY(doc->setParameter("sun.elevation_deg", e, &error));
            QTest::qWait(800);
        }
        ViewportWindow* v = w_->viewport();
        Watchdog watchdog;
        QSignalSpy frames(v, &ViewportWindow::frameRendered);
        for (const auto& [name, value] : std::vector<std::pair<const char*, nlohmann::json>>{
                 {"sun.elevation_deg", 30.0}, {"sun.elevation_deg", 40.0}, {"terrain.albedo_mode", "constant"},
                 {"sun.elevation_deg", 30.0}, {"terrain.albedo_mode", "ramp"}, {"sun.elevation_deg", 40.0}}) {
            QVERIFY2(doc->setParameter(name, value, &error), qPrintable(error));
            QTest::qWait(700);
        }
        const qint64 worst = watchdog.worst();
        qInfo() << "sky and albedo edits with frames in flight:" << frames.count() << "frames, longest UI stall" << worst
                << "ms";
        QVERIFY2(frames.count() >= 6, "the edits drew no frames");
        QVERIFY2(worst <= 50, qPrintable(QString("the UI thread stalled %1 ms").arg(worst)));
        for (const auto& [name, value] : std::vector<std::pair<const char*, nlohmann::json>>{
                 {"water.enabled", water}, {"sky.mode", sky}, {"sun.elevation_deg", elevation},
                 {"terrain.albedo_mode", albedo}})
            QVERIFY2(doc->setParameter(name, value, &error), qPrintable(error));
    }

    // Fog and shadows turned on and off each draw the terrain and the water with pipelines not
    // built before (lavapipe compiles the terrain's in 120-170 ms): they are built on a worker
    // while the window shows the frame before, and the UI thread does not wait for them.
    void featureTogglesNeverHoldTheUiThread() {
        QString error;
        QVERIFY(w_->document()->setParameter("camera.exposure_mode", "manual", &error));
        ViewportWindow* v = w_->viewport();
        ProjectRenderer* r = v->renderer();
        QVERIFY(r);
        v->renderNow();
        QVERIFY(settlesQuiet(v));
        const TerrainRenderer& t = r->renderer();
        const size_t inlineBefore = t.pipelinesBuiltInline(), workersBefore = t.pipelinesBuiltOnWorkers();
        const bool fog = w_->document()->project().scene.fog.enabled;
        const bool shadows = w_->document()->project().scene.shadows.enabled;
        Watchdog watchdog;
        const std::vector<std::pair<std::string, bool>> toggles = {
            {"fog.enabled", !fog}, {"shadows.enabled", !shadows}, {"fog.enabled", fog}, {"shadows.enabled", shadows}};
        for (const auto& [name, on] : toggles) {
            QSignalSpy frames(v, &ViewportWindow::frameRendered);
            QVERIFY(w_->document()->setParameter(name, on, &error));
            QTRY_VERIFY_WITH_TIMEOUT(frames.count() >= 1, 10000);
            QVERIFY(settlesQuiet(v));
        }
        const qint64 worst = watchdog.worst();
        qInfo() << "fog and shadow toggles: longest UI stall" << worst << "ms, pipelines built on workers"
                << t.pipelinesBuiltOnWorkers() - workersBefore;
        QVERIFY2(worst <= 50, qPrintable(QString("the UI thread stalled %1 ms").arg(worst)));
        QCOMPARE(t.pipelinesBuiltInline(), inlineBefore);
        // The three new variants of the terrain: fog toggled, then shadows toggled with it, then
        // shadows toggled alone (the fourth toggle is back at the first frame's).
        QVERIFY(t.pipelinesBuiltOnWorkers() >= workersBefore + 3);
    }

    // A new terrain and an undo back: the DEM loads on a worker, the old renderer goes once the
    // device has finished its frames (the new one's uploads would wait behind them: 0.4-0.55 s on
    // lavapipe), and the first frame's pipelines and exposure meter are drawn behind the window's
    // frames. The UI thread is never held for any of it.
    // 16-50 ms here, where the waits for the device and the first meter held it 460-600 ms.
    void newTerrainsNeverHoldTheUiThread() {
        importThenUndoWithoutStalls(fs::path(TERRALUX_TEST_DATA) / "dem" / "rainier_crop.tif", 46.85,
                                    "Rainier crop");
    }

    // An 80 km tile (N42E001, 986 × 1 348 vertices once reprojected): its renderer is made on a
    // worker (it held the UI thread 350 ms), its first horizon map swept on one before its first
    // frame (90 ms), and its AO's maps built and uploaded on the AO's worker (100-500 ms); import
    // and undo held the UI thread 437 ms, now 31-63 ms.
    void aMountainTileNeverHoldsTheUiThread() {
        const fs::path dem = fs::path(TERRALUX_SHARED_DATA) / "dem" / "N42E001.hgt";
        if (!fs::exists(dem)) QSKIP("../shared/data/dem/N42E001.hgt is absent");
        importThenUndoWithoutStalls(dem, 42.5, "N42E001", [](ProjectRenderer& r) {
            QVERIFY(size_t(r.heightfield().width()) * size_t(r.heightfield().depth()) > 1'000'000);
            // Its AO lands (its maps made off the UI thread) and the frames draw with it.
            QTRY_VERIFY_WITH_TIMEOUT(r.renderer().hasAmbientOcclusion(), 60000);
            QVERIFY(r.renderer().sunHorizonSweeps() >= 1);
        });
    }

    void rejectedValuesLeaveTheProject() {
        auto* elevation = w_->findChild<QDoubleSpinBox*>("param.sun.elevation_deg");
        QVERIFY(elevation);
        const double before = elevation->value();
        QString error;
        QVERIFY(!w_->document()->setParameter("probe_volumes[0].grid_dims", nlohmann::json{100, 100}, &error));
        QVERIFY(error.contains("product <= 4096"));
        QCOMPARE(elevation->value(), before);
        QCOMPARE(w_->document()->project().scene.probeVolumes[0].gridDims[0], 8);
    }

    void bakeThroughTheUiThenCancelLeavesFilesUntouched() {
        w_->findChild<QPushButton*>("bake.start")->click();
        auto* progress = w_->findChild<QProgressBar*>("bake.progress");
        QVERIFY(QTest::qWaitFor([&] { return !w_->bakes()->running() && progress->value() == 100; }, 60000));
        const fs::path shprobe = kOut / "bake" / "sh_coeffs" / "probes.shprobe";
        QVERIFY(fs::exists(shprobe));
        QVERIFY(fs::exists(kOut / "bake" / "scene.gltf"));
        QVERIFY(waitForProbes(*w_, "last bake"));
        const std::string bytes = fileBytes(shprobe), gltf = fileBytes(kOut / "bake" / "scene.gltf");

        // The report is a table, a column per volume, with the figures of bake_report.json.
        auto* table = w_->findChild<QTableWidget*>("bake.report");
        QVERIFY(table);
        const nlohmann::json report = nlohmann::json::parse(fileBytes(kOut / "bake" / "bake_report.json"));
        QCOMPARE(table->columnCount(), 1);
        QCOMPARE(table->horizontalHeaderItem(0)->text(), QString("probes"));
        auto figure = [&](const QString& row) {
            for (int r = 0; r < table->rowCount(); ++r)
                if (table->verticalHeaderItem(r)->text() == row) return table->item(r, 0)->text();
            return QString("no row " + row);
        };
        const nlohmann::json& volume = report["volumes"][0];
        QCOMPARE(figure("Probes"), QLocale().toString(volume["probes"].get<double>(), 'f', 0));
        QCOMPARE(figure("Invalid (in terrain)"), QLocale().toString(volume["invalid_probes"].get<double>(), 'f', 0));
        QCOMPARE(figure("Rays"), QLocale().toString(volume["rays"].get<double>(), 'f', 0));
        // What each probe traced for the preset's standard error: min / median / max.
        const nlohmann::json& perProbe = volume["rays_per_probe"];
        QCOMPARE(figure("Rays per probe (min / median / max)"),
                 QLocale().toString(perProbe["min"].get<double>(), 'f', 0) + " / " +
                     QLocale().toString(perProbe["median"].get<double>(), 'f', 0) + " / " +
                     QLocale().toString(perProbe["max"].get<double>(), 'f', 0));
        QCOMPARE(figure("Interpolation error (p95)"),
                 QString("%1 %").arg(volume["error_map"]["p95"].get<double>() * 100.0, 0, 'f', 2));
        QCOMPARE(figure("Standard error (mean)"),
                 QString("%1 %").arg(volume["standard_error"]["mean"].get<double>() * 100.0, 0, 'f', 2));
        QVERIFY(figure("File size").endsWith("KiB"));
        // The default 8 x 8 grid interpolates badly: the dock says what to set instead.
        auto* advice = w_->findChild<QLabel*>("bake.suggestions");
        QVERIFY(advice);
        QCOMPARE(advice->isVisible(), !volume["suggestions"].empty());
        QVERIFY(!volume["suggestions"].empty());
        QVERIFY2(advice->text().contains("probe_volumes[0].grid_dims=") && advice->text().contains("probes, about"),
                 qPrintable(advice->text()));
        // With the error the suggested grid was measured to give.
        const nlohmann::json& predicted = volume["suggestions"][0]["predicted_error"];
        QVERIFY2(advice->text().contains(QString(", error %1 % mean / %2 % p95")
                                             .arg(predicted["mean"].get<double>() * 100.0, 0, 'f', 2)
                                             .arg(predicted["p95"].get<double>() * 100.0, 0, 'f', 2)),
                 qPrintable(advice->text()));

        QString error;
        QVERIFY(w_->document()->setParameter("bake.quality", "reference", &error));
        QVERIFY(w_->document()->setParameter("probe_volumes[0].grid_dims", nlohmann::json{64, 64}, &error));
        w_->findChild<QPushButton*>("bake.start")->click();
        QVERIFY(w_->bakes()->running());
        QCOMPARE(table->rowCount(), 0);  // a new bake clears the last one's report
        QTest::qWait(300);
        w_->findChild<QPushButton*>("bake.cancel")->click();
        QVERIFY(QTest::qWaitFor([&] { return !w_->bakes()->running(); }, 60000));
        QVERIFY(w_->findChild<QLabel*>("bake.eta")->text().contains("cancelled"));
        QCOMPARE(fileBytes(shprobe), bytes);
        QCOMPARE(fileBytes(kOut / "bake" / "scene.gltf"), gltf);
    }

    void everyDebugViewMatchesTheRenderCommand() {
        w_->findChild<QPushButton*>("bake.start")->click();
        QVERIFY(QTest::qWaitFor([&] { return !w_->bakes()->running(); }, 60000));
        QVERIFY(waitForProbes(*w_, "last bake"));
        // The command line's path: a fresh renderer of the same project, loading the same bake.
        vk::VulkanContext ctx;
        ProjectRenderer reference(ctx, w_->document()->project());
        QCOMPARE(reference.loadProbes(false), size_t(1));
        auto* selector = w_->findChild<QComboBox*>("viewport.debugView");
        QVERIFY(selector);
        QCOMPARE(selector->count(), int(debugViews().size()));
        auto* legend = w_->findChild<QLabel*>("status.legend");
        QVERIFY(legend);
        for (int i = 0; i < selector->count(); ++i) {
            selector->setCurrentIndex(i);
            w_->viewport()->renderNow();
            const RenderedImage shown = w_->viewport()->grabImage();
            // The diagnostic views keep their colour key in the status bar.
            const int number = selector->itemData(i).toInt();
            QCOMPARE(legend->text().contains("red"), findDebugView(number)->needs.probeDiagnostics);
            // The LPV views name their own exposure: E/π over the bound volumes' light range.
            if (number == kViewLpvCascade0 || number == kViewLpvAll) {
                const std::optional<double> range = w_->viewport()->renderer()->renderer().lpvViewRange();
                QVERIFY(range.has_value());
                QTRY_COMPARE(legend->text(), QString::fromUtf8("E/π ÷ %1 W/(m²·sr)").arg(*range, 0, 'g', 3));
            }
            RenderRequest q;
            q.width = shown.width;
            q.height = shown.height;
            q.debugView = selector->itemData(i).toInt();
            const RenderedImage cli = reference.render(q, w_->viewport()->camera());
            const auto d = test::compareImages(shown.rgba, cli.rgba, shown.width, shown.height);
            QVERIFY2(d.maxAbs <= 1.0 / 255.0, qPrintable(selector->itemText(i) + QString(": max diff %1").arg(d.maxAbs)));
        }
    }

    void corruptDemGetsADialogAndKeepsTheTerrain() {
        const int width = w_->document()->terrain().heightfield.width();
        const nlohmann::json project = w_->document()->json();
        const int undoSteps = w_->document()->undoStack()->count();
        QString dialogText;
        // The import runs on a worker, so the dialog comes when it fails; poll for it.
        QTimer poll;
        poll.setInterval(20);
        connect(&poll, &QTimer::timeout, [&] {
            if (auto* box = qobject_cast<QMessageBox*>(QApplication::activeModalWidget())) {
                dialogText = box->objectName() + ": " + box->text();
                box->accept();
            }
        });
        poll.start();
        const QString bad = QString::fromStdString((fs::path(TERRALUX_TEST_DATA) / "dem" / "not_a_raster.tif").string());
        QVERIFY(w_->importDemFile(bad));
        QVERIFY(w_->findChild<QProgressBar*>("status.terrainBusy")->isVisible() || !dialogText.isEmpty() || w_->document()->terrainLoading());
        QTRY_VERIFY_WITH_TIMEOUT(!dialogText.isEmpty(), 20000);
        poll.stop();
        QVERIFY(!w_->document()->terrainLoading());
        QVERIFY(!w_->findChild<QProgressBar*>("status.terrainBusy")->isVisible());
        QVERIFY2(dialogText.startsWith("errorDialog: ") && dialogText.contains("not_a_raster.tif"), qPrintable(dialogText));
        QCOMPARE(w_->document()->terrain().heightfield.width(), width);
        QVERIFY(w_->document()->json() == project);
        QCOMPARE(w_->document()->undoStack()->count(), undoSteps);
    }

    void openingAProjectWhoseDemFailsKeepsTheOpenOne() {
        const nlohmann::json before = w_->document()->json();
        const QString file = QString::fromStdString((kOut / "bad_dem.terralux.json").string());
        {
            nlohmann::json p = before;
            p["terrain"]["dem"] = (fs::path(TERRALUX_TEST_DATA) / "dem" / "not_a_raster.tif").string();
            std::ofstream(file.toStdString()) << p.dump(2);
        }
        QString dialogText;
        QTimer poll;
        poll.setInterval(20);
        connect(&poll, &QTimer::timeout, [&] {
            if (auto* box = qobject_cast<QMessageBox*>(QApplication::activeModalWidget())) {
                dialogText = box->text();
                box->accept();
            }
        });
        poll.start();
        QVERIFY(w_->openProject(file));  // the file itself is fine; its terrain is not
        QTRY_VERIFY_WITH_TIMEOUT(!dialogText.isEmpty(), 20000);
        QVERIFY2(dialogText.contains("not_a_raster.tif"), qPrintable(dialogText));
        QVERIFY(w_->document()->json() == before);
        QVERIFY(w_->document()->fileName() != file);
    }

    // A bake whose recorded settings differ from the project's is labelled stale, as --render says.
    void aStaleBakeIsMarked() {
        const fs::path dir = kOut / "stale";
        fs::remove_all(dir);
        fs::create_directories(dir);
        // The bake beside the project: an untitled project's relative out_dir is the launch folder.
        Project p = loadEffectiveProject("", {"bake.quality=draft", "bake.error_map_resolution=0",
                                              "export.out_dir=" + (dir / "bake").string()}, "", nullptr);
        const fs::path file = dir / "p.terralux.json";
        saveProject(p, file);
        BakeRequest bake;
        bake.project = loadProject(file, nullptr);
        runBake(bake, nullptr, nullptr);
        QVERIFY(w_->openProject(QString::fromStdString(file.string())));
        w_->document()->waitForTerrain();
        // The renderer for the opened terrain is made once the device has drawn the old one's frames.
        auto* label = w_->findChild<QLabel*>("status.probes");
        QTRY_VERIFY2(label->text().contains("(last bake)"), qPrintable(label->text()));
        // The same project with another grid: its bake no longer matches.
        p.scene.probeVolumes[0].gridDims = {6, 1, 6};
        saveProject(p, file);
        QVERIFY(w_->openProject(QString::fromStdString(file.string())));
        w_->document()->waitForTerrain();
        QTRY_VERIFY2(label->text().contains("last bake, stale: probe_volumes[0].grid_dims: baked [8,8], now [6,6]"),
                     qPrintable(label->text()));
    }

    void saveAndReopenKeepsEveryParameter() {
        QString error;
        QVERIFY(w_->document()->setParameter("sun.elevation_deg", 12.5, &error));
        QVERIFY(w_->document()->setParameter("terrain.albedo", nlohmann::json{0.2, 0.25, 0.3}, &error));
        const QString file = QString::fromStdString((kOut / "saved.terralux.json").string());
        QVERIFY(w_->document()->saveAs(file, &error));
        const nlohmann::json saved = projectToJson(w_->document()->project());
        w_->document()->newProject();
        QVERIFY(projectToJson(w_->document()->project()) != saved);
        QVERIFY(w_->openProject(file));
        w_->document()->waitForTerrain();
        QCOMPARE(QString::fromStdString(projectToJson(w_->document()->project()).dump()), QString::fromStdString(saved.dump()));
        QCOMPARE(w_->findChild<QDoubleSpinBox*>("param.sun.elevation_deg")->value(), 12.5);
    }

    void autosaveIsOfferedBackAfterACrash() {
        QString error;
        QVERIFY(w_->document()->setParameter("sun.azimuth_deg", 77.0, &error));
        w_->autosave();
        const fs::path autosave = kOut / "autosave" / "autosave.terralux.json";
        QVERIFY(fs::exists(autosave));
        // A crash: the window goes away without closing, so the autosave stays behind.
        w_.reset();
        w_ = std::make_unique<MainWindow>();
        w_->show();
        QCOMPARE(w_->document()->project().scene.sun.azimuthDeg, 135.0);
        QString asked;
        QTimer::singleShot(200, [&] {
            if (auto* box = qobject_cast<QMessageBox*>(QApplication::activeModalWidget())) {
                asked = box->objectName();
                box->button(QMessageBox::Yes)->click();
            }
        });
        w_->offerRecovery();
        QCOMPARE(asked, QString("recoveryDialog"));
        w_->document()->waitForTerrain();
        QCOMPARE(w_->document()->project().scene.sun.azimuthDeg, 77.0);
        QVERIFY(!fs::exists(autosave));
    }

    // Every dock row takes its limits from the parameter table: walk the table, not a list.
    void dockLimitsEqualTheTable() {
        int checked = 0;
        for (const ParameterSpec& spec : parameterTable()) {
            if (!spec.uiRow) continue;
            const QString name = QString::fromStdString(uiObjectName(spec));
            const QString where = QString::fromStdString(spec.path) + " (" + name + ")";
            switch (spec.type) {
            case ParamType::Number: {
                auto* spin = w_->findChild<QDoubleSpinBox*>(name);
                QVERIFY2(spin, qPrintable(where));
                const double step = std::pow(10.0, -spin->decimals());
                QCOMPARE(spin->minimum(), spec.nullable() ? uiMinimum(spec) - step : uiMinimum(spec));
                QCOMPARE(spin->maximum(), spec.max);
                QCOMPARE(spin->specialValueText().isEmpty(), !spec.nullable());
                break;
            }
            case ParamType::Integer: {
                auto* spin = w_->findChild<QSpinBox*>(name);
                QVERIFY2(spin, qPrintable(where));
                QCOMPARE(spin->minimum(), int(spec.min) - (spec.nullable() ? 1 : 0));
                QCOMPARE(spin->specialValueText().toStdString(), spec.nullable() ? autoShort(spec) : spec.zeroText);
                QCOMPARE(spin->maximum(), int(std::min<double>(spec.max, std::numeric_limits<int>::max())));
                break;
            }
            case ParamType::NumberList:
            case ParamType::IntegerList:
                if (spec.colorList) {
                    // One colour button per triple (the dialog keeps each in [0, 1]).
                    for (int i = 0; i < spec.maxItems / 3; ++i)
                        QVERIFY2(w_->findChild<QPushButton*>(name + "." + QString::number(i)), qPrintable(where));
                    QVERIFY(!w_->findChild<QWidget*>(name + "." + QString::number(spec.maxItems / 3)));
                    break;
                }
                QVERIFY2(w_->findChild<QAbstractSpinBox*>(name + ".0"), qPrintable(where));
                QCOMPARE(bool(w_->findChild<QCheckBox*>(name + ".auto")), spec.nullable());
                for (int i = 0; i < spec.maxItems; ++i) {
                    const QString element = name + "." + QString::number(i);
                    if (spec.type == ParamType::IntegerList) {
                        auto* spin = w_->findChild<QSpinBox*>(element);
                        QVERIFY2(spin, qPrintable(element));
                        QCOMPARE(spin->minimum(), int(spec.min));
                        QCOMPARE(spin->maximum(), int(std::min<double>(spec.max, std::numeric_limits<int>::max())));
                    } else {
                        auto* spin = w_->findChild<QDoubleSpinBox*>(element);
                        QVERIFY2(spin, qPrintable(element));
                        QCOMPARE(spin->minimum(), uiMinimum(spec));
                        QCOMPARE(spin->maximum(), spec.max);
                    }
                }
                break;
            case ParamType::Choice: {
                auto* combo = w_->findChild<QComboBox*>(name);
                QVERIFY2(combo, qPrintable(where));
                QCOMPARE(combo->count(), int(spec.choices.size()));
                for (int i = 0; i < combo->count(); ++i)
                    QCOMPARE(combo->itemText(i).toStdString(), spec.choices[size_t(i)]);
                break;
            }
            case ParamType::Boolean:
                QVERIFY2(w_->findChild<QCheckBox*>(name), qPrintable(where));
                break;
            case ParamType::Color:
                QVERIFY2(w_->findChild<QPushButton*>(name), qPrintable(where));
                break;
            case ParamType::String:
                QVERIFY2(w_->findChild<QLineEdit*>(name), qPrintable(where));
                break;
            }
            ++checked;
        }
        QVERIFY(checked > 30);
    }


    // The Shadows and Atmosphere docks hold an editor for every row of their sections, shown
    // where the scene reads it.
    void shadowAndAtmosphereDocksHoldTheirRows() {
        for (const QString& name : {QString("dock.shadows"), QString("dock.atmosphere"), QString("dock.surface"),
                                    QString("dock.ao")}) {
            auto* dock = w_->findChild<QDockWidget*>(name);
            QVERIFY2(dock, qPrintable(name));
            dock->raise();
            int rows = 0;
            for (const ParameterSpec& spec : parameterTable()) {
                if (!spec.uiRow || QString::fromStdString(parameterDock(spec).objectName) != name) continue;
                const QString editorName = QString::fromStdString(uiObjectName(spec));
                QWidget* editor = dock->findChild<QWidget*>(editorName);
                if (!editor) editor = dock->findChild<QWidget*>(editorName + ".0");
                QVERIFY2(editor, qPrintable(name + ": " + editorName));
                QCOMPARE(rowOf(editor)->isVisibleTo(dock), spec.isRead(w_->document()->project().scene, 0));
                ++rows;
            }
            QVERIFY(rows >= (name == "dock.ao" ? 4 : 8));
        }
        QCOMPARE(w_->findChild<QDockWidget*>("dock.shadows")->windowTitle(), QString("Shadows"));
        QCOMPARE(w_->findChild<QDockWidget*>("dock.surface")->windowTitle(), QString("Surface"));
        QCOMPARE(w_->findChild<QDockWidget*>("dock.ao")->windowTitle(), QString("Ambient Occlusion"));
        // The surface rows left the Terrain dock.
        QVERIFY(!w_->findChild<QDockWidget*>("dock.terrain")->findChild<QWidget*>("param.terrain.roughness"));
        QVERIFY(w_->findChild<QDockWidget*>("dock.surface")->findChild<QPushButton*>("surface.importAlbedo"));
        QCOMPARE(w_->findChild<QDockWidget*>("dock.atmosphere")->windowTitle(), QString("Atmosphere"));
        QVERIFY(w_->findChild<QDockWidget*>("dock.atmosphere")->findChild<QDoubleSpinBox*>("param.camera.exposure_ev"));
        QVERIFY(w_->findChild<QDockWidget*>("dock.shadows")->findChild<CascadeSplitChart*>("shadows.splitChart"));
        QVERIFY(w_->findChild<QDockWidget*>("dock.shadows")->findChild<QPushButton*>("shadows.showCascades"));
        // Manual mode shows the split row, and the fog rows follow fog.enabled.
        w_->findChild<QComboBox*>("param.shadows.split_mode")->setCurrentText("manual");
        auto* shadowsDock = w_->findChild<QDockWidget*>("dock.shadows");
        QVERIFY(rowOf(w_->findChild<QWidget*>("param.shadows.splits.0"))->isVisibleTo(shadowsDock));
        QVERIFY(!rowOf(w_->findChild<QWidget*>("param.shadows.split_lambda"))->isVisibleTo(shadowsDock));
        w_->findChild<QCheckBox*>("param.fog.enabled")->setChecked(false);
        auto* atmosphereDock = w_->findChild<QDockWidget*>("dock.atmosphere");
        QVERIFY(!rowOf(w_->findChild<QWidget*>("param.fog.density"))->isVisibleTo(atmosphereDock));
        QVERIFY(rowOf(w_->findChild<QWidget*>("param.camera.exposure_ev"))->isVisibleTo(atmosphereDock));
        // Exposure: metered by histogram by default, with its adaptation; manual trades that row
        // for the camera's EV100.
        auto* exposureMode = w_->findChild<QComboBox*>("param.camera.exposure_mode");
        QVERIFY(exposureMode && atmosphereDock->isAncestorOf(exposureMode));
        QCOMPARE(exposureMode->currentText(), QString("histogram"));
        QWidget* ev100 = rowOf(w_->findChild<QWidget*>("param.camera.ev100"));
        QWidget* adaptation = rowOf(w_->findChild<QWidget*>("param.camera.adaptation_s"));
        QVERIFY(!ev100->isVisibleTo(atmosphereDock) && adaptation->isVisibleTo(atmosphereDock));
        exposureMode->setCurrentText("manual");
        QVERIFY(ev100->isVisibleTo(atmosphereDock) && !adaptation->isVisibleTo(atmosphereDock));
        exposureMode->setCurrentText("histogram");
    }

    // sun.mode date_time: the Sun & Sky dock trades the angles for a date, a time of day on a
    // slider and a place that says where the DEM is; the slider moves the sun through the day.
    void dateAndTimePlaceTheSun() {
        ProjectDocument& doc = *w_->document();
        auto* dock = w_->findChild<QDockWidget*>("dock.sunSky");
        QVERIFY(dock);
        dock->raise();
        auto* mode = w_->findChild<QComboBox*>("param.sun.mode");
        QVERIFY(mode);
        QVERIFY(!rowOf(w_->findChild<QWidget*>("param.sun.time_h"))->isVisibleTo(dock));
        mode->setCurrentText("date_time");
        QCOMPARE(doc.project().scene.sun.mode, SunMode::DateTime);
        QVERIFY(!rowOf(w_->findChild<QWidget*>("param.sun.azimuth_deg"))->isVisibleTo(dock));
        for (const char* name : {"param.sun.date", "param.sun.time_h", "param.sun.utc_offset_h", "param.sun.latitude_deg"})
            QVERIFY2(rowOf(w_->findChild<QWidget*>(name))->isVisibleTo(dock), name);
        // "auto" names the sample's place and its nominal zone.
        const QString latitude = w_->findChild<QDoubleSpinBox*>("param.sun.latitude_deg")->text();
        QVERIFY2(latitude.contains(QLocale().toString(doc.terrain().heightfield.geo.latitudeDeg, 'f', 4)), qPrintable(latitude));
        QVERIFY2(w_->findChild<QDoubleSpinBox*>("param.sun.utc_offset_h")->text().contains(QLocale().toString(-8.0, 'f', 2)),
                 qPrintable(w_->findChild<QDoubleSpinBox*>("param.sun.utc_offset_h")->text()));
        auto* slider = w_->findChild<QSlider*>("param.sun.time_h.slider");
        QVERIFY(slider);
        slider->setValue(250);  // 06:00
        QCOMPARE(doc.project().scene.sun.timeH, 6.0);
        const SunAngles morning = sunAnglesOf(doc.project().scene, doc.terrain().heightfield);
        slider->setValue(750);  // 18:00
        QCOMPARE(doc.project().scene.sun.timeH, 18.0);
        const SunAngles evening = sunAnglesOf(doc.project().scene, doc.terrain().heightfield);
        QVERIFY(morning.azimuthDeg < 90.0 && evening.azimuthDeg > 270.0);
        QVERIFY(evening.elevationDeg > 0.0 && evening.elevationDeg < 20.0);
        auto* position = w_->findChild<QLabel*>("sun.position");
        QVERIFY(position && position->isVisibleTo(dock));
        QVERIFY2(position->text().startsWith(QString("Sun at azimuth %1°").arg(evening.azimuthDeg, 0, 'f', 1)),
                 qPrintable(position->text()));
        w_->viewport()->renderNow();
        QTest::qWait(300);
        QVERIFY(w_->screen()->grabWindow(0, w_->x(), w_->y(), w_->frameGeometry().width(), w_->frameGeometry().height())
                    .save(QString::fromStdString((kOut / "sun_date_time.png").string())));
        // A date the calendar does not have is refused and leaves the project as it was.
        auto* date = w_->findChild<QLineEdit*>("param.sun.date");
        QVERIFY(date);
        date->setText("2026-02-30");
        QMetaObject::invokeMethod(date, "editingFinished");
        QCOMPARE(doc.project().scene.sun.date, std::string("2026-06-21"));
        date->setText("2026-12-21");
        QMetaObject::invokeMethod(date, "editingFinished");
        QCOMPARE(doc.project().scene.sun.date, std::string("2026-12-21"));
        QVERIFY(sunAnglesOf(doc.project().scene, doc.terrain().heightfield).elevationDeg < evening.elevationDeg);
        while (doc.undoStack()->canUndo()) doc.undoStack()->undo();
        QCOMPARE(doc.project().scene.sun.mode, SunMode::Manual);
        QVERIFY(rowOf(w_->findChild<QWidget*>("param.sun.azimuth_deg"))->isVisibleTo(dock));
        QVERIFY(!position->isVisibleTo(dock));
    }

    // Shadow, fog and exposure edits draw the next frame with the new value and bake nothing; undo
    // gives the same pixels back. A sky edit, by contrast, bakes the preview again.
    void shadowAndFogEditsRedrawWithoutBaking() {
        QApplication::setActiveWindow(w_.get());
        QVERIFY(QTest::qWaitForWindowActive(w_.get()));
        w_->viewport()->renderNow();
        const RenderedImage before = w_->viewport()->grabImage();
        const unsigned previews = w_->previewsStarted();
        QSignalSpy frames(w_->viewport(), &ViewportWindow::frameRendered);
        auto check = [&](QWidget* editor, const char* dock, const std::function<void()>& edit, const char* what) {
            w_->findChild<QDockWidget*>(dock)->raise();
            frames.clear();
            const int steps = w_->document()->undoStack()->index();
            edit();
            QCOMPARE(w_->document()->undoStack()->index(), steps + 1);
            // The edit asked for a frame, and that frame draws the new value.
            QVERIFY2(frames.wait(2000) || !frames.isEmpty(), what);
            const RenderedImage edited = w_->viewport()->grabImage();
            const auto d = test::compareImages(edited.rgba, before.rgba, before.width, before.height);
            QVERIFY2(d.maxAbs > 8.0 / 255.0, qPrintable(QString("%1 changed the image by %2").arg(what).arg(d.maxAbs)));
            // Ctrl+Z from the dock's own editor reaches the document.
            editor->setFocus();
            QTest::keySequence(editor, QKeySequence::Undo);
            QCOMPARE(w_->document()->undoStack()->index(), steps);
            const RenderedImage undone = w_->viewport()->grabImage();
            QVERIFY2(undone.rgba == before.rgba, qPrintable(QString("undo of %1 is not the same image").arg(what)));
        };
        auto* shadowsOn = w_->findChild<QCheckBox*>("param.shadows.enabled");
        QVERIFY(shadowsOn && shadowsOn->isChecked());
        check(shadowsOn, "dock.shadows", [&] { shadowsOn->setChecked(false); }, "shadows off");
        QVERIFY(w_->document()->project().scene.shadows.enabled);
        auto* fogOn = w_->findChild<QCheckBox*>("param.fog.enabled");
        QVERIFY(fogOn && fogOn->isChecked());
        check(fogOn, "dock.atmosphere", [&] { fogOn->setChecked(false); }, "fog off");
        auto* density = w_->findChild<QDoubleSpinBox*>("param.fog.density");
        QVERIFY(density);
        check(density, "dock.atmosphere", [&] { density->setValue(density->value() * 20.0); }, "fog density");
        auto* exposure = w_->findChild<QDoubleSpinBox*>("param.camera.exposure_ev");
        QVERIFY(exposure);
        check(exposure, "dock.atmosphere", [&] { exposure->setValue(1.0); }, "exposure");
        auto* aoOn = w_->findChild<QCheckBox*>("param.ao.enabled");
        QVERIFY(aoOn && aoOn->isChecked());
        check(aoOn, "dock.ao", [&] { aoOn->setChecked(false); }, "ambient occlusion off");
        auto* roughness = w_->findChild<QDoubleSpinBox*>("param.terrain.roughness");
        QVERIFY(roughness);
        check(roughness, "dock.surface", [&] { roughness->setValue(0.25); }, "roughness");
        auto* filter = w_->findChild<QComboBox*>("param.shadows.filter");
        QVERIFY(filter);
        check(filter, "dock.shadows", [&] { filter->setCurrentText("hard"); }, "shadow filter");
        // An edit of the whole section (manual mode with its splits) is no different.
        w_->findChild<QComboBox*>("param.shadows.split_mode")->setCurrentText("manual");
        QCOMPARE(w_->document()->project().scene.shadows.splitMode, SplitMode::Manual);
        // Past the preview's debounce: no preview and no bake started, the preview still bound.
        QTest::qWait(400);
        QCOMPARE(w_->previewsStarted(), previews);
        QVERIFY(!w_->bakes()->running());
        QCOMPARE(w_->probeSource(), QString("draft preview"));

        QString error;
        QVERIFY(w_->document()->setParameter("sky.intensity", 2.0, &error));
        QTRY_VERIFY_WITH_TIMEOUT(w_->previewsStarted() == previews + 1, 5000);
    }

    // The horizon AO is computed on a worker with its progress in the dock, then lands in the
    // viewport; the settings it was computed for are said.
    void ambientOcclusionIsComputedOnAWorker() {
        auto* dock = w_->findChild<QDockWidget*>("dock.ao");
        dock->raise();
        auto* status = w_->findChild<QLabel*>("ao.status");
        auto* progress = w_->findChild<QProgressBar*>("ao.progress");
        QVERIFY(status && progress);
        QTRY_VERIFY_WITH_TIMEOUT(status->text().startsWith("32 directions over"), 20000);
        QVERIFY(!progress->isVisibleTo(dock));
        QSignalSpy frames(w_->viewport(), &ViewportWindow::frameRendered);
        w_->findChild<QSpinBox*>("param.ao.directions")->setValue(8);
        QTRY_VERIFY_WITH_TIMEOUT(status->text().startsWith("8 directions over"), 20000);
        QVERIFY(!progress->isVisibleTo(dock));
        QTRY_VERIFY_WITH_TIMEOUT(!frames.isEmpty(), 5000);
        // Off: no worker, and the dock says what that means.
        w_->findChild<QCheckBox*>("param.ao.enabled")->setChecked(false);
        QVERIFY(status->text().startsWith("Off"));
        QVERIFY(w_->document()->undoStack()->canUndo());
    }

    // The ramp colours the viewport at once (and the preview bakes again: the bake reflects with it).
    void albedoRampColoursTheTerrain() {
        // A folder with no bake: one current for the ramp (an earlier test's) would be shown
        // instead of a preview.
        QString error;
        QVERIFY(w_->document()->setParameter("export.out_dir", (kOut / "no_bake").string(), &error));
        w_->findChild<QDockWidget*>("dock.surface")->raise();
        w_->findChild<QComboBox*>("param.terrain.albedo_mode")->setCurrentText("constant");
        w_->viewport()->renderNow();
        const RenderedImage before = w_->viewport()->grabImage();
        const unsigned previews = w_->previewsStarted();
        w_->findChild<QComboBox*>("param.terrain.albedo_mode")->setCurrentText("ramp");
        QCOMPARE(w_->document()->project().scene.terrain.albedoMode, AlbedoMode::Ramp);
        QVERIFY(rowOf(w_->findChild<QWidget*>("param.terrain.ramp_heights.0"))->isVisibleTo(w_->findChild<QDockWidget*>("dock.surface")));
        w_->viewport()->renderNow();
        const RenderedImage after = w_->viewport()->grabImage();
        const auto d = test::compareImages(after.rgba, before.rgba, before.width, before.height);
        QVERIFY2(d.meanAbs > 4.0 / 255.0, qPrintable(QString("the ramp changed the image by %1").arg(d.meanAbs)));
        QTRY_VERIFY_WITH_TIMEOUT(w_->previewsStarted() > previews, 5000);

        // One colour button per stop; picking a colour rewrites that stop's triple only.
        auto* dock = w_->findChild<QDockWidget*>("dock.surface");
        // The dock widens to its rows (the stops appeared after it was built): none is clipped.
        auto* area = dock->findChild<QScrollArea*>();
        QVERIFY(area);
        QTRY_VERIFY(area->viewport()->width() >= area->widget()->minimumSizeHint().width());
        const size_t stops = w_->document()->project().scene.terrain.ramp.heights.size();
        for (size_t k = 0; k < size_t(kMaxRampStops); ++k) {
            auto* button = w_->findChild<QPushButton*>(QString("param.terrain.ramp_colors.%1").arg(k));
            QVERIFY(button);
            QCOMPARE(button->isVisibleTo(dock), k < stops);
        }
        const nlohmann::json colorsBefore = w_->document()->value("terrain.ramp_colors");
        // Each stop shows its numbers, whole, on its swatch (they were only in the tooltip).
        for (size_t k = 0; k < stops; ++k) {
            auto* button = w_->findChild<QPushButton*>(QString("param.terrain.ramp_colors.%1").arg(k));
            const QString numbers = QString("%1, %2, %3")
                                        .arg(colorsBefore[3 * k].get<double>(), 0, 'g', 3)
                                        .arg(colorsBefore[3 * k + 1].get<double>(), 0, 'g', 3)
                                        .arg(colorsBefore[3 * k + 2].get<double>(), 0, 'g', 3);
            QCOMPARE(button->text(), numbers);
            QTRY_VERIFY2(button->fontMetrics().horizontalAdvance(numbers) <= button->contentsRect().width(),
                         qPrintable(QString("stop %1: %2 px of text on a %3 px button").arg(k)
                                        .arg(button->fontMetrics().horizontalAdvance(numbers)).arg(button->contentsRect().width())));
        }
        QTimer::singleShot(200, [] {
            auto* dialog = qobject_cast<QColorDialog*>(QApplication::activeModalWidget());
            if (!dialog) return;
            dialog->setCurrentColor(QColor::fromRgbF(1.0f, 0.0f, 0.0f));
            dialog->accept();
        });
        w_->findChild<QPushButton*>("param.terrain.ramp_colors.1")->click();
        const nlohmann::json colorsAfter = w_->document()->value("terrain.ramp_colors");
        QCOMPARE(colorsAfter.size(), colorsBefore.size());
        QCOMPARE(colorsAfter[3].get<double>(), 1.0);
        QCOMPARE(colorsAfter[4].get<double>(), 0.0);
        QCOMPARE(colorsAfter[5].get<double>(), 0.0);
        for (size_t i : {0, 1, 2, 6, 7, 8}) QCOMPARE(colorsAfter[i], colorsBefore[i]);
        QVERIFY(w_->findChild<QPushButton*>("param.terrain.ramp_colors.1")->toolTip() == "1, 0, 0");
    }

    // Every edit refreshes every open form, so a row whose value did not change must cost
    // nothing: a sun edit re-polishes no ramp swatch and repaints no surface row, and a closed
    // dock's form skips the edit until it is shown. The probe volume list keeps its items.
    void formsLeaveUnchangedRowsAlone() {
        class Counter : public QObject {
        public:
            std::map<QEvent::Type, int> seen;
            bool eventFilter(QObject*, QEvent* e) override {
                ++seen[e->type()];
                return false;
            }
        };
        ProjectDocument* doc = w_->document();
        const int undoIndex = doc->undoStack()->index();
        QString error;
        QVERIFY(doc->setParameter("terrain.albedo_mode", "ramp", &error));
        auto* surfaceDock = w_->findChild<QDockWidget*>("dock.surface");
        surfaceDock->raise();
        w_->findChild<QDockWidget*>("dock.probeVolumes")->raise();
        auto* swatch = surfaceDock->findChild<QPushButton*>("param.terrain.ramp_colors.0");
        auto* roughness = surfaceDock->findChild<QDoubleSpinBox*>("param.terrain.roughness");
        auto* volumes = w_->findChild<QListWidget*>("volumes.list");
        QVERIFY(swatch && roughness && volumes && volumes->count() > 0);
        QTRY_VERIFY(swatch->isVisible() && roughness->isVisible() && volumes->isVisible());
        // In view, or the rows would draw nothing either way.
        auto* scroll = qobject_cast<QScrollArea*>(surfaceDock->widget());
        if (!scroll) scroll = surfaceDock->findChild<QScrollArea*>();
        QVERIFY(scroll);
        scroll->ensureWidgetVisible(roughness);
        QVERIFY(!roughness->visibleRegion().isEmpty());
        QTest::qWait(200);  // the raise's own repaints land first
        Counter swatchEvents, roughnessEvents;
        swatch->installEventFilter(&swatchEvents);
        roughness->installEventFilter(&roughnessEvents);
        const QListWidgetItem* firstVolume = volumes->item(0);
        const double elevation = doc->project().scene.sun.elevationDeg;
        QVERIFY(doc->setParameter("sun.elevation_deg", elevation + 3.0, &error));
        QTest::qWait(200);
        QCOMPARE(swatchEvents.seen[QEvent::StyleChange], 0);
        QCOMPARE(swatchEvents.seen[QEvent::ToolTipChange], 0);
        QCOMPARE(roughnessEvents.seen[QEvent::Paint], 0);
        QCOMPARE(volumes->item(0), firstVolume);
        // The counters see a change: the edited row repaints, the edited swatch re-polishes.
        const double before = doc->project().scene.terrain.roughness;
        QVERIFY(doc->setParameter("terrain.roughness", before > 0.5 ? 0.3 : 0.7, &error));
        QTRY_VERIFY(roughnessEvents.seen[QEvent::Paint] > 0);
        nlohmann::json colors = doc->value("terrain.ramp_colors");
        colors[0] = colors[0].get<double>() > 0.5 ? 0.25 : 0.75;
        QVERIFY(doc->setParameter("terrain.ramp_colors", colors, &error));
        QCOMPARE(swatchEvents.seen[QEvent::StyleChange], 1);
        swatch->removeEventFilter(&swatchEvents);
        roughness->removeEventFilter(&roughnessEvents);

        // A closed dock's form keeps what it showed, and catches up when opened. (Behind another
        // dock's tab a form still refreshes: Qt moves the dock out of the window, not hides it,
        // and with its unchanged rows left alone a refresh costs little.)
        surfaceDock->close();
        QTRY_VERIFY(!roughness->isVisible());
        const double shown = roughness->value();
        QVERIFY(doc->setParameter("terrain.roughness", shown > 0.5 ? 0.35 : 0.65, &error));
        QCOMPARE(roughness->value(), shown);
        surfaceDock->show();
        surfaceDock->raise();
        QTRY_VERIFY(roughness->isVisible());
        QCOMPARE(roughness->value(), doc->project().scene.terrain.roughness);
        doc->undoStack()->setIndex(undoIndex);
        QCOMPARE(doc->project().scene.terrain.roughness, before);
        QCOMPARE(doc->project().scene.sun.elevationDeg, elevation);
    }

    // A metered exposure: an edit that darkens the frame meters again, and the viewport's shown
    // exposure follows the meter over frames with the authored time constant, then stops drawing;
    // the status bar shows the EV100 as it moves.
    void meteredExposureAdaptsInTheViewport() {
        QString error;
        QVERIFY(w_->document()->setParameter("camera.exposure_mode", "histogram", &error));
        // A second's time constant: two stops stay more than 0.1 EV from the meter for 3 s, which
        // a loaded machine's polling cannot miss (at 0.4 s the window was 1.2 s, and CI missed it).
        QVERIFY(w_->document()->setParameter("camera.adaptation_s", 1.0, &error));
        ProjectRenderer* r = w_->viewport()->renderer();
        QVERIFY(r);
        w_->viewport()->renderNow();
        QTRY_VERIFY_WITH_TIMEOUT(!r->exposureAdapting(), 10000);
        const double before = r->meteredEv100();
        QVERIFY(std::isfinite(before));
        QTRY_VERIFY_WITH_TIMEOUT(w_->findChild<QLabel*>("status.frame")->text().contains("EV100"), 5000);
        // A quarter of the sun and the sky: all the light two stops down (a preview bake follows;
        // the meter reads each new frame).
        const size_t meterings = r->meterings();
        const double sun = w_->document()->project().scene.sun.illuminance;
        const double sky = w_->document()->project().scene.sky.intensity;
        QVERIFY(w_->document()->setParameter("sun.illuminance", sun / 4.0, &error));
        QVERIFY(w_->document()->setParameter("sky.intensity", sky / 4.0, &error));
        QTRY_VERIFY_WITH_TIMEOUT(r->meterings() > meterings && r->exposureAdapting(), 10000);
        // On the way: the shown exposure has not jumped to the new reading.
        QVERIFY2(r->shownEv100() > r->meteredEv100() + 0.1,
                 qPrintable(QString("shown %1, metered %2").arg(r->shownEv100()).arg(r->meteredEv100())));
        // Both at once: a later meter (the preview bake landing) may start the eye adapting again.
        QTRY_VERIFY_WITH_TIMEOUT(!r->exposureAdapting() && std::abs(r->meteredEv100() - (before - 2.0)) < 0.1, 15000);
        QVERIFY(std::abs(r->shownEv100() - r->meteredEv100()) <= 0.02);
        // The label follows the frame's presentation, which comes once the device has drawn it.
        QTRY_VERIFY_WITH_TIMEOUT(
            w_->findChild<QLabel*>("status.frame")->text().contains(QString("EV100 %1").arg(r->shownEv100(), 0, 'f', 2)), 5000);
        // Adapted: no frame without a change, and a redraw of the same view does not meter again.
        QVERIFY(settlesQuiet(w_->viewport()));
        // The status bar also says what the terrain's level of detail drew, and how close to the DEM.
        const TerrainRenderer::LodChoice& lod = r->renderer().lastLod();
        QVERIFY(lod.triangles > 0);
        QTRY_VERIFY_WITH_TIMEOUT(w_->findChild<QLabel*>("status.frame")->text().contains(
                                     QString(" tris, %1 px").arg(lod.screenErrorPixels, 0, 'f', 2)),
                                 5000);
        QVERIFY2(w_->findChild<QLabel*>("status.frame")->text().contains(
                     QString("terrain %1 k tris").arg(double(lod.triangles) / 1e3, 0, 'f', 0)),
                 qPrintable(w_->findChild<QLabel*>("status.frame")->text()));
        const size_t settled = r->meterings();
        for (int i = 0; i < 3; ++i) w_->viewport()->renderNow();
        QCOMPARE(r->meterings(), settled);
        w_->document()->undoStack()->undo();
        w_->document()->undoStack()->undo();
        QCOMPARE(w_->document()->project().scene.sun.illuminance, sun);
    }

    // Dynamic resolution: with a budget no frame meets, a camera move draws at a quarter of the
    // side (the status bar says so), and the full resolution follows once the moves stop; with
    // it off every frame is full. The budget comes from the device: 100 ms on lavapipe.
    void dynamicResolutionHoldsTheBudgetAndRefines() {
        ViewportWindow* v = w_->viewport();
        QCOMPARE(v->resolution().budgetMilliseconds(), ViewportWindow::kCpuFrameBudgetMs);
        auto* action = w_->findChild<QAction*>("action.dynamicResolution");
        QVERIFY(action && action->isCheckable() && action->isChecked());
        v->setFrameBudget(1e-3);
        v->renderNow();  // a frame measured (its GPU time arrives with the next ones)
        QVERIFY(settlesQuiet(v));
        QSignalSpy frames(v, &ViewportWindow::frameRendered);
        QTest::keyClick(v, Qt::Key_Left);
        QTRY_VERIFY_WITH_TIMEOUT(frames.count() > 0, 5000);
        QTRY_VERIFY_WITH_TIMEOUT(v->presentedScale() < 0.3, 5000);
        QVERIFY(w_->findChild<QLabel*>("status.frame")->text().contains("6 % res"));
        // No change for the refine delay: one frame at full resolution.
        QTRY_VERIFY_WITH_TIMEOUT(v->presentedScale() == 1.0, 5000);
        QVERIFY(!w_->findChild<QLabel*>("status.frame")->text().contains("% res"));
        QVERIFY(settlesQuiet(v));
        action->setChecked(false);
        QVERIFY(!v->dynamicResolution());
        QSignalSpy fullFrames(v, &ViewportWindow::frameRendered);
        QTest::keyClick(v, Qt::Key_Right);
        QTRY_VERIFY_WITH_TIMEOUT(fullFrames.count() > 0, 5000);
        QCOMPARE(v->presentedScale(), 1.0);
        QVERIFY(settlesQuiet(v));
        QCOMPARE(v->presentedScale(), 1.0);
        action->setChecked(true);
        v->setFrameBudget(ViewportWindow::kCpuFrameBudgetMs);
    }

    // A camera move from the viewport keeps the exposure (the viewport writes only its own keys).
    void cameraMovesKeepTheExposure() {
        auto* exposure = w_->findChild<QDoubleSpinBox*>("param.camera.exposure_ev");
        QVERIFY(exposure);
        exposure->setValue(1.5);
        QCOMPARE(w_->document()->project().scene.camera.exposureEv, 1.5);
        const double azimuth = w_->document()->project().scene.camera.azimuthDeg;
        QTest::keyClick(w_->viewport(), Qt::Key_Left);
        QVERIFY(w_->document()->project().scene.camera.azimuthDeg != azimuth);
        QCOMPARE(w_->document()->project().scene.camera.exposureEv, 1.5);
        QCOMPARE(exposure->value(), 1.5);
    }

    // The shadow, cascade and fog views after edits in the docks are the command line's images.
    void shadowAndFogViewsMatchTheRenderCommand() {
        w_->findChild<QComboBox*>("param.shadows.split_mode")->setCurrentText("manual");
        QVERIFY(w_->document()->value("shadows.splits").is_array());
        w_->findChild<QSpinBox*>("param.shadows.cascades")->setValue(3);
        w_->findChild<QComboBox*>("param.shadows.filter")->setCurrentText("pcf");
        auto* density = w_->findChild<QDoubleSpinBox*>("param.fog.density");
        density->setValue(density->value() * 10.0);
        // Probe lighting off on both sides: the reference has no bake to light with.
        w_->findChild<QCheckBox*>("viewport.probes")->setChecked(false);
        vk::VulkanContext ctx;
        ProjectRenderer reference(ctx, w_->document()->project());
        auto* selector = w_->findChild<QComboBox*>("viewport.debugView");
        for (const int view : {kViewShadow, kViewCascades, kViewFog}) {
            selector->setCurrentIndex(selector->findData(view));
            w_->viewport()->renderNow();
            const RenderedImage shown = w_->viewport()->grabImage();
            RenderRequest q;
            q.width = shown.width;
            q.height = shown.height;
            q.debugView = view;
            q.probes = false;
            const RenderedImage cli = reference.render(q, w_->viewport()->camera());
            const auto d = test::compareImages(shown.rgba, cli.rgba, shown.width, shown.height);
            QVERIFY2(d.maxAbs <= 1.0 / 255.0, qPrintable(selector->currentText() + QString(": max diff %1").arg(d.maxAbs)));
        }
    }

    // The split chart: switching to manual writes the practical splits, a drag moves one split in
    // one undoable edit, a new cascade count resamples the splits; Show cascades toggles view 34.
    // With "auto" ticked, Origin and Spacing showed 0.00 m and 0.01 m; they show what auto-span
    // resolves to on the terrain: the sample's 7 650 m over 8 probes is 1 092.86 m a step.
    void autoOriginAndSpacingShowTheResolvedValues() {
        ProjectDocument& doc = *w_->document();
        QVERIFY(doc.value("probe_volumes[0].spacing").is_null());
        w_->findChild<QDockWidget*>("dock.probeVolumes")->raise();
        auto* spacing = w_->findChild<QDoubleSpinBox*>("param.volume.spacing.0");
        auto* spacingZ = w_->findChild<QDoubleSpinBox*>("param.volume.spacing.1");
        auto* origin = w_->findChild<QDoubleSpinBox*>("param.volume.origin.0");
        QVERIFY(spacing && spacingZ && origin);
        QVERIFY(w_->findChild<QCheckBox*>("param.volume.spacing.auto")->isChecked());
        QVERIFY(!spacing->isEnabled());
        const Heightfield& hf = doc.terrain().heightfield;
        const double span = hf.maxX() - hf.minX();
        QCOMPARE(spacing->text(), QString::number(span / 7.0, 'f', spacing->decimals()) + " m");
        QCOMPARE(spacingZ->value(), spacing->value());
        QCOMPARE(origin->value(), double(hf.minX()));
        // The fallback blend's "2 × spacing" says how far that is here: twice 1 092.86 m.
        auto* blend = w_->findChild<QDoubleSpinBox*>("param.volume.fallback_blend_distance");
        QVERIFY(blend);
        QCOMPARE(blend->text(), QString("2 × spacing (%1 m)").arg(QLocale().toString(2.0 * span / 7.0, 'f', 1)));
        // Typed 32 x 8, the grid spans the square footprint in uneven steps; the dock shows both
        // (they were only in the bake's probes.json).
        QString error;
        QVERIFY2(doc.setParameter("probe_volumes[0].grid_dims", nlohmann::json{32, 8}, &error), qPrintable(error));
        QCOMPARE(spacing->text(), QString::number(span / 31.0, 'f', spacing->decimals()) + " m");
        QCOMPARE(spacingZ->text(), QString::number((hf.maxZ() - hf.minZ()) / 7.0, 'f', spacingZ->decimals()) + " m");
        w_->findChild<QAction*>("action.undo")->trigger();
        // The reflection grid's likewise (4 x 4 over the footprint).
        QVERIFY2(doc.setParameter("reflection_probes.enabled", true, &error), qPrintable(error));
        auto* reflection = w_->findChild<QDoubleSpinBox*>("param.reflection_probes.spacing.0");
        QVERIFY(reflection);
        QCOMPARE(reflection->value(), std::round(span / 3.0 * 100.0) / 100.0);
        auto* reflectionBlend = w_->findChild<QDoubleSpinBox*>("param.reflection_probes.fallback_blend_distance");
        QVERIFY(reflectionBlend);
        QCOMPARE(reflectionBlend->text(),
                 QString("2 × spacing (%1 m)").arg(QLocale().toString(2.0 * span / 3.0, 'f', 1)));
        doc.undoStack()->undo();
    }

    // Undo names an edit in words, not by its JSON path ("Undo Set probe_volumes[0].grid_dims").
    void undoLabelsAreWords() {
        ProjectDocument& doc = *w_->document();
        QUndoStack& undo = *doc.undoStack();
        const int start = undo.index();
        QString error;
        QVERIFY2(doc.setParameter("probe_volumes[0].grid_dims", nlohmann::json{9, 9}, &error), qPrintable(error));
        QCOMPARE(undo.undoText(), QString("Set Grid (probes) of volume 'probes'"));
        QVERIFY2(doc.setParameters({{"fog.scale_height", 900.0}, {"sun.elevation_deg", 20.0}}, &error), qPrintable(error));
        QCOMPARE(undo.undoText(), QString("Set Scale height (fog), Sun elevation"));
        while (undo.index() > start) undo.undo();
    }

    void splitChartEditsTheSplits() {
        ProjectDocument& doc = *w_->document();
        w_->findChild<QDockWidget*>("dock.shadows")->raise();
        auto* chart = w_->findChild<CascadeSplitChart*>("shadows.splitChart");
        QVERIFY(chart);
        QTRY_VERIFY(chart->isVisible());
        QUndoStack& undo = *doc.undoStack();
        const int start = undo.index();
        const ShadowSettings practical = doc.project().scene.shadows;
        QCOMPARE(practical.splitMode, SplitMode::Practical);
        QVERIFY(doc.value("shadows.splits").is_null());
        // The chart spans the renderer's range: the project camera at the viewport's aspect.
        QCOMPARE(doc.viewAspect(), double(w_->viewport()->width()) / w_->viewport()->height());
        const CascadeRange drawn = chart->range();
        {
            const Heightfield& hf = doc.terrain().heightfield;
            const CascadeRange expected = cascadeRange(practical, OrbitCamera::fromSettings(doc.project().scene.camera, hf),
                                                       float(doc.viewAspect()), {hf.minX(), hf.minHeight(), hf.minZ()},
                                                       {hf.maxX(), hf.maxHeight(), hf.maxZ()});
            QCOMPARE(drawn.ends, expected.ends);
            QCOMPARE(drawn.nearDistance, expected.nearDistance);
            QCOMPARE(drawn.ends.size(), size_t(4));
        }

        // Practical mode: the handles do not move, and say why.
        QVERIFY(chart->toolTip().contains("manual"));
        const QPoint h1 = chart->handlePosition(1);
        QTest::mousePress(chart, Qt::LeftButton, {}, h1);
        QTest::mouseMove(chart, h1 + QPoint(40, 0));
        QTest::mouseRelease(chart, Qt::LeftButton, {}, h1 + QPoint(40, 0));
        QCOMPARE(undo.index(), start);

        // Switching to manual writes the practical inner ends with it: one edit, nothing rejected.
        auto* mode = w_->findChild<QComboBox*>("param.shadows.split_mode");
        mode->setCurrentText("manual");
        QCOMPARE(undo.index(), start + 1);
        QCOMPARE(doc.project().scene.shadows.splitMode, SplitMode::Manual);
        const nlohmann::json written = doc.value("shadows.splits");
        QVERIFY2(written.is_array() && written.size() == 3, written.dump().c_str());
        for (size_t i = 0; i < 3; ++i)
            QVERIFY2(std::abs(written[i].get<double>() - drawn.ends[i]) <= 0.5, written.dump().c_str());
        QCOMPARE(w_->findChild<QDoubleSpinBox*>("param.shadows.splits.0")->value(), written[0].get<double>());
        QVERIFY(chart->toolTip().contains("Drag"));
        undo.undo();
        QCOMPARE(doc.project().scene.shadows.splitMode, SplitMode::Practical);
        QVERIFY(doc.value("shadows.splits").is_null());
        QCOMPARE(mode->currentText(), QString("practical"));
        undo.redo();
        QCOMPARE(doc.value("shadows.splits"), written);

        // A drag of the middle handle: the chart follows the mouse, the release is one edit.
        const std::vector<double> splits = *doc.project().scene.shadows.splits;
        const QPoint from = chart->handlePosition(1);
        const QPoint to = from + QPoint(25, 0);
        QTest::mousePress(chart, Qt::LeftButton, {}, from);
        QTest::mouseMove(chart, from + QPoint(10, 0));
        QTest::mouseMove(chart, to);
        QVERIFY(chart->range().ends[1] > splits[1]);  // live in the chart
        QCOMPARE(doc.project().scene.shadows.splits->at(1), splits[1]);  // not yet in the document
        QTest::mouseRelease(chart, Qt::LeftButton, {}, to);
        QCOMPARE(undo.index(), start + 2);
        std::vector<double> dragged = *doc.project().scene.shadows.splits;
        QCOMPARE(dragged[0], splits[0]);
        QCOMPARE(dragged[2], splits[2]);
        const double metresPerPixel = (drawn.farDistance - drawn.nearDistance) / (chart->width() - 16);
        QVERIFY2(std::abs(dragged[1] - chart->distanceAt(to.x())) <= 1.0 + metresPerPixel,
                 qPrintable(QString("%1 vs %2").arg(dragged[1]).arg(chart->distanceAt(to.x()))));
        QCOMPARE(dragged[1], std::round(dragged[1]));  // whole metres, as the dock edits them
        undo.undo();
        QCOMPARE(*doc.project().scene.shadows.splits, splits);
        undo.redo();

        // Dragged past its neighbour, a split stops short of it.
        const QPoint first = chart->handlePosition(0);
        QTest::mousePress(chart, Qt::LeftButton, {}, first);
        QTest::mouseMove(chart, QPoint(chart->width() - 2, first.y()));
        QTest::mouseRelease(chart, Qt::LeftButton, {}, QPoint(chart->width() - 2, first.y()));
        QCOMPARE(undo.index(), start + 3);
        dragged = *doc.project().scene.shadows.splits;
        QVERIFY(dragged[0] < dragged[1] && dragged[0] >= dragged[1] - 1.0);
        // The last one stays below the shadow distance.
        QString error;
        QVERIFY(doc.setParameter("shadows.max_distance", std::round(drawn.farDistance * 0.9), &error));
        const QPoint last = chart->handlePosition(2);
        QTest::mousePress(chart, Qt::LeftButton, {}, last);
        QTest::mouseMove(chart, QPoint(chart->width() + 50, last.y()));
        QTest::mouseRelease(chart, Qt::LeftButton, {}, QPoint(chart->width() + 50, last.y()));
        QVERIFY(doc.project().scene.shadows.splits->back() < *doc.project().scene.shadows.maxDistance);
        QVERIFY(doc.project().scene.shadows.splits->back() > dragged[2]);

        // Another cascade count in manual mode resamples the splits in the same edit.
        const std::vector<double> four = *doc.project().scene.shadows.splits;
        auto* cascades = w_->findChild<QSpinBox*>("param.shadows.cascades");
        int steps = undo.index();
        cascades->setValue(2);
        QCOMPARE(undo.index(), steps + 1);
        QCOMPARE(doc.project().scene.shadows.cascades, 2);
        QCOMPARE(*doc.project().scene.shadows.splits, std::vector<double>{four[0]});
        QCOMPARE(chart->range().ends.size(), size_t(2));
        cascades->setValue(4);
        QCOMPARE(undo.index(), steps + 2);
        const std::vector<double> resampled = *doc.project().scene.shadows.splits;
        QCOMPARE(resampled.size(), size_t(3));
        QCOMPARE(resampled[0], four[0]);
        QVERIFY(resampled[1] > resampled[0] && resampled[2] > resampled[1]);
        QVERIFY(resampled[2] < *doc.project().scene.shadows.maxDistance);
        undo.undo();
        undo.undo();
        QCOMPARE(doc.project().scene.shadows.cascades, 4);
        QCOMPARE(*doc.project().scene.shadows.splits, four);
        // A shadow distance below the last split keeps the splits before it.
        QVERIFY(doc.setParameter("shadows.max_distance", std::round(0.5 * (four[1] + four[2])), &error));
        QCOMPARE(doc.project().scene.shadows.splits->at(1), four[1]);
        QVERIFY(doc.project().scene.shadows.splits->at(2) < *doc.project().scene.shadows.maxDistance);
        // Writing the splits themselves still obeys the table.
        QVERIFY(!doc.setParameter("shadows.splits", nullptr, &error));
        QVERIFY(!doc.setParameter("shadows.splits", nlohmann::json{100.0, 50.0, 200.0}, &error));

        // Show cascades: view 34 and back to the view before, following the selector.
        auto* show = w_->findChild<QPushButton*>("shadows.showCascades");
        auto* selector = w_->findChild<QComboBox*>("viewport.debugView");
        QVERIFY(show && show->isCheckable() && !show->isChecked());
        selector->setCurrentIndex(selector->findData(kViewShadow));
        show->click();
        QCOMPARE(selector->currentData().toInt(), kViewCascades);
        QCOMPARE(w_->viewport()->debugView(), kViewCascades);
        show->click();
        QCOMPARE(selector->currentData().toInt(), kViewShadow);
        QCOMPARE(w_->viewport()->debugView(), kViewShadow);
        selector->setCurrentIndex(selector->findData(kViewCascades));
        QVERIFY(show->isChecked());
        selector->setCurrentIndex(selector->findData(kViewFog));
        QVERIFY(!show->isChecked());
        show->click();
        QCOMPARE(selector->currentData().toInt(), kViewCascades);
        show->click();
        QCOMPARE(selector->currentData().toInt(), kViewFog);
    }

    // Dock conventions, each a tracker item (one window for all: cheap checks share its start).
    void dockEditingConventions() {
        // Undo/Redo typed in any dock reach the document; a line edit's own typing undoes first (undoShortcutsReachTheDocumentFromAnyDock)
        {
            QApplication::setActiveWindow(w_.get());
            QVERIFY(QTest::qWaitForWindowActive(w_.get()));
            w_->findChild<QDockWidget*>("dock.sunSky")->raise();
            auto* elevation = w_->findChild<QDoubleSpinBox*>("param.sun.elevation_deg");
            QVERIFY(elevation);
            const double before = elevation->value();
            elevation->setFocus();
            elevation->setValue(12.0);
            QCOMPARE(w_->document()->project().scene.sun.elevationDeg, 12.0);
            QTest::keySequence(elevation, QKeySequence::Undo);
            QCOMPARE(w_->document()->project().scene.sun.elevationDeg, before);
            QCOMPARE(elevation->value(), before);
            QTest::keySequence(elevation, QKeySequence::Redo);
            QCOMPARE(w_->document()->project().scene.sun.elevationDeg, 12.0);

            w_->findChild<QDockWidget*>("dock.bakeExport")->raise();
            auto* out = w_->findChild<QLineEdit*>("param.export.out_dir");
            QVERIFY(out);
            const QString committed = out->text();
            const int steps = w_->document()->undoStack()->index();
            out->setFocus();
            out->end(false);
            QTest::keyClicks(out, "_typed");
            QTest::keySequence(out, QKeySequence::Undo);
            QCOMPARE(out->text(), committed);
            QCOMPARE(w_->document()->undoStack()->index(), steps);
            QTest::keySequence(out, QKeySequence::Undo);  // nothing typed left: the document's turn
            QCOMPARE(w_->document()->undoStack()->index(), steps - 1);
        }
        // Dock titles are plain text (dockTitlesShowOneAmpersand)
        {
            QCOMPARE(w_->findChild<QDockWidget*>("dock.sunSky")->windowTitle(), QString("Sun & Sky"));
            QCOMPARE(w_->findChild<QDockWidget*>("dock.bakeExport")->windowTitle(), QString("Bake & Export"));
            // Menus read '&' as a mnemonic: the Panels entries double it to show one.
            QCOMPARE(w_->findChild<QDockWidget*>("dock.sunSky")->toggleViewAction()->text(), QString("Sun && Sky"));
        }
        // Rows the placement does not read are hidden, walking the table (rowsThePlacementIgnoresAreHidden)
        {
            auto* panel = w_->findChild<ProbeVolumesPanel*>();
            QVERIFY(panel);
            auto* placement = w_->findChild<QComboBox*>("param.volume.placement");
            for (const QString mode : {"adaptive", "box", "terrain"}) {
                placement->setCurrentText(mode);
                const SceneDescription& scene = w_->document()->project().scene;
                int hidden = 0;
                for (const ParameterSpec& spec : parameterTable()) {
                    if (!spec.uiRow || !spec.perVolume()) continue;
                    const QString name = QString::fromStdString(uiObjectName(spec));
                    QWidget* editor = w_->findChild<QWidget*>(name);
                    if (!editor) editor = w_->findChild<QWidget*>(name + ".0");
                    QVERIFY2(editor, qPrintable(name));
                    QCOMPARE(rowOf(editor)->isVisibleTo(panel), spec.isRead(scene, 0));
                    hidden += !spec.isRead(scene, 0);
        }
            QVERIFY(hidden > 0);
        }
        placement->setCurrentText("adaptive");
        QVERIFY(!rowOf(w_->findChild<QWidget*>("param.volume.grid_dims.0"))->isVisibleTo(panel));
        QVERIFY(rowOf(w_->findChild<QWidget*>("param.volume.adaptive.tolerance"))->isVisibleTo(panel));
        placement->setCurrentText("terrain");
        QVERIFY(rowOf(w_->findChild<QWidget*>("param.volume.grid_dims.0"))->isVisibleTo(panel));
        QVERIFY(!rowOf(w_->findChild<QWidget*>("param.volume.adaptive.tolerance"))->isVisibleTo(panel));
            }
        // Sun and sky rows the sky mode does not read are hidden, walking the table (rowsTheSkyModeIgnoresAreHidden)
        {
            auto* dock = w_->findChild<QDockWidget*>("dock.sunSky");
            dock->raise();
            auto* mode = w_->findChild<QComboBox*>("param.sky.mode");
            auto* follow = w_->findChild<QCheckBox*>("param.sun.follow_sky");
            QVERIFY(mode && follow);
            auto rowsMatchTheTable = [&] {
                const SceneDescription& scene = w_->document()->project().scene;
                int hidden = 0;
                for (const ParameterSpec& spec : parameterTable()) {
                    // The scenarios' rows: scenariosAreEditedShownAndBlended.
                    if (!spec.uiRow || spec.perScenario() || parameterDock(spec).objectName != "dock.sunSky") continue;
                    const QString name = QString::fromStdString(uiObjectName(spec));
                    QWidget* editor = w_->findChild<QWidget*>(name);
                    QVERIFY2(editor, qPrintable(name));
                    QCOMPARE(rowOf(editor)->isVisibleTo(dock), spec.isRead(scene, 0));
                    hidden += !spec.isRead(scene, 0);
                }
                QVERIFY(hidden > 0);
            };
            mode->setCurrentText("physical");
            QCOMPARE(w_->document()->project().scene.sky.mode, SkyMode::Physical);
            rowsMatchTheTable();
            QVERIFY(!rowOf(w_->findChild<QWidget*>("param.sun.illuminance"))->isVisibleTo(dock));
            QVERIFY(rowOf(w_->findChild<QWidget*>("param.sky.turbidity"))->isVisibleTo(dock));
            QVERIFY(!rowOf(w_->findChild<QWidget*>("param.sky.luminance"))->isVisibleTo(dock));
            follow->setChecked(false);
            QVERIFY(!w_->document()->project().scene.sun.followSky);
            rowsMatchTheTable();
            QVERIFY(rowOf(w_->findChild<QWidget*>("param.sun.illuminance"))->isVisibleTo(dock));
            // An image sky with a sun in it, followed: no authored sun row shows, and the dock says
            // where the image's sun stands (a 2 x 2-texel sun at azimuth -61.9 degrees, 16.9 up).
            follow->setChecked(true);
            const fs::path sunHdr = kOut / "sun.exr";
            std::vector<float> rgba(size_t(64) * 32 * 4, 1.0f);
            for (int y : {12, 13})
                for (int x : {20, 21})
                    for (int c = 0; c < 3; ++c) rgba[(size_t(y) * 64 + size_t(x)) * 4 + size_t(c)] = 12800.0f;
            writeImage(sunHdr, 64, 32, rgba);
            QString error;
            QVERIFY2(w_->document()->setParameter("sky.hdr", sunHdr.string(), &error), qPrintable(error));
            mode->setCurrentText("hdr");
            QCOMPARE(w_->document()->project().scene.sky.mode, SkyMode::Hdr);
            rowsMatchTheTable();
            for (const char* row : {"param.sun.azimuth_deg", "param.sun.illuminance", "param.sun.angular_radius_deg", "param.sun.mode"})
                QVERIFY2(!rowOf(w_->findChild<QWidget*>(row))->isVisibleTo(dock), row);
            QVERIFY(rowOf(follow)->isVisibleTo(dock));
            auto* position = w_->findChild<QLabel*>("sun.position");
            QVERIFY(position && position->isVisibleTo(dock));
            QVERIFY2(position->text().startsWith(QString("Sun from the image at azimuth %1°, 16.").arg(-61.9, 0, 'f', 1)) &&
                         position->text().contains("° above the horizon"),
                     qPrintable(position->text()));
            follow->setChecked(false);
            rowsMatchTheTable();
            QVERIFY(rowOf(w_->findChild<QWidget*>("param.sun.azimuth_deg"))->isVisibleTo(dock));
            QVERIFY(!position->isVisibleTo(dock));
            mode->setCurrentText("uniform");
            rowsMatchTheTable();
            QVERIFY(!rowOf(w_->findChild<QWidget*>("param.sky.turbidity"))->isVisibleTo(dock));
            QVERIFY(!rowOf(w_->findChild<QWidget*>("param.sky.hdr"))->isVisibleTo(dock));
            QVERIFY(rowOf(w_->findChild<QWidget*>("param.sky.color"))->isVisibleTo(dock));
            // The uniform sky's luminance is entered in cd/m² and lights the preview as such.
            auto* luminance = w_->findChild<QDoubleSpinBox*>("param.sky.luminance");
            QVERIFY(luminance && rowOf(luminance)->isVisibleTo(dock));
            QVERIFY(luminance->suffix().contains("cd/m"));
            luminance->setValue(8000.0);
            QCOMPARE(w_->document()->project().scene.sky.luminance, 8000.0);
            w_->document()->undoStack()->undo();
            QCOMPARE(w_->document()->project().scene.sky.luminance, 5000.0);
            // The wheel over a field without focus scrolls the dock and leaves the value alone.
            luminance->clearFocus();
            QVERIFY(!luminance->hasFocus());
            QWheelEvent wheel(QPointF(5, 5), luminance->mapToGlobal(QPointF(5, 5)), QPoint(), QPoint(0, -120),
                              Qt::NoButton, Qt::NoModifier, Qt::NoScrollPhase, false);
            QApplication::sendEvent(luminance, &wheel);
            QCOMPARE(luminance->value(), 5000.0);
            QCOMPARE(w_->document()->project().scene.sky.luminance, 5000.0);
            QCOMPARE(luminance->focusPolicy(), Qt::StrongFocus);
        }
        // Max_resolution 'source' sends 0, never null (maxResolutionSourceSendsZero)
        {
            auto* spin = w_->findChild<QSpinBox*>("param.terrain.max_resolution");
            QVERIFY(spin);
            spin->setValue(128);
            w_->document()->waitForTerrain();
            QCOMPARE(w_->document()->terrain().heightfield.width(), 128);
            spin->setValue(0);
            w_->document()->waitForTerrain();
            const nlohmann::json v = w_->document()->value("terrain.max_resolution");
            QVERIFY2(v.is_number_integer() && v.get<int>() == 0, v.dump().c_str());
            QCOMPARE(spin->text(), QString("source"));
            QCOMPARE(w_->document()->terrain().heightfield.width(), 256);
        }
    }

    // Where projects and bakes go: Save As suffix, an untitled bake, an export elsewhere.
    void savingAndBakingGoWhereTheUserSays() {
        // An untitled project asks where to bake; the dock shows the absolute folder (untitledProjectBakesWhereTheUserSays)
        {
            quickBakeSettings(*w_->document());
            auto* where = w_->findChild<QLabel*>("bake.outputPath");
            QVERIFY(where);
            QVERIFY2(where->text().contains(QString::fromStdString((kOut / "bake").string())), qPrintable(where->text()));
            QString error;
            QVERIFY(w_->document()->setParameter("export.out_dir", "bake", &error));
            QVERIFY2(where->text().contains("save the project first"), qPrintable(where->text()));
            const bool launchHadBake = fs::exists(fs::current_path() / "bake");
            const fs::path folder = kOut / "untitled";
            fs::create_directories(folder);
            DialogAnswers answers({[](QWidget* w) {
                                       if (w->objectName() != "bakeLocationDialog") return false;
                                       w->findChild<QPushButton*>("bakeLocation.save")->click();
                                       return true;
                                   },
                                   pickFile("saveDialog", folder / "project")});
            w_->findChild<QPushButton*>("bake.start")->click();
            QVERIFY(answers.done());
            QVERIFY(QTest::qWaitFor([&] { return !w_->bakes()->running() && w_->probeSource() == "last bake"; }, 60000));
            QVERIFY(fs::exists(folder / "project.terralux.json"));
            QVERIFY(fs::exists(folder / "bake" / "sh_coeffs" / "probes.shprobe"));
            QCOMPARE(fs::exists(fs::current_path() / "bake"), launchHadBake);
            QVERIFY2(where->text().endsWith(QString::fromStdString((folder / "bake").string())), qPrintable(where->text()));
        }
        // After Export to folder the viewport shows the exported probes, labelled so (exportedProbesAreWhatTheViewportShows)
        {
            // The project's own bake (above) is bound: 8 x 8 probes.
            QCOMPARE(w_->probeSource(), QString("last bake"));
            QCOMPARE(w_->boundProbeCount(), size_t(64));
            QString error;
            QVERIFY(w_->document()->setParameter("probe_volumes[0].grid_dims", nlohmann::json{4, 4}, &error));
            const fs::path folder = kOut / "exported";
            fs::create_directories(folder);
            DialogAnswers answers({pickFile("exportDialog", folder)});
            w_->findChild<QAction*>("action.export")->trigger();
            QVERIFY(answers.done());
            const QString source = "export in " + QString::fromStdString(fs::absolute(folder).lexically_normal().string());
            QVERIFY(QTest::qWaitFor([&] { return !w_->bakes()->running() && w_->probeSource() == source; }, 60000));
            QVERIFY(fs::exists(folder / "sh_coeffs" / "probes.shprobe"));
            QCOMPARE(w_->boundProbeCount(), size_t(16));
            QVERIFY(w_->findChild<QLabel*>("status.probes")->text().contains(source));
        }
        // A name without .json gets .terralux.json (saveAsAddsTheProjectSuffix)
        {
            QCOMPARE(MainWindow::projectFileName("a.json"), QString("a.json"));
            QCOMPARE(MainWindow::projectFileName("a.terralux"), QString("a.terralux.json"));
            QCOMPARE(MainWindow::projectFileName("a.v2"), QString("a.v2.terralux.json"));
            const fs::path typed = kOut / "named";
            DialogAnswers answers({pickFile("saveDialog", typed)});
            w_->findChild<QAction*>("action.saveAs")->trigger();
            QVERIFY(answers.done());
            const fs::path saved = kOut / "named.terralux.json";
            QVERIFY2(fs::exists(saved), qPrintable(w_->document()->fileName()));
            QVERIFY(!fs::exists(typed));
            QCOMPARE(fs::path(w_->document()->fileName().toStdString()), saved);
        }
    }

    // Adaptive volumes in the window: the status bar counts the preview, placement errors show.
    void adaptivePreviewCountsAndErrors() {
        // The status bar counts what the preview holds (statusCountsTheProbesTheViewportHolds)
        {
            quickBakeSettings(*w_->document());
            QString error;
            QVERIFY(w_->document()->setParameter("probe_volumes[0].placement", "adaptive", &error));
            // A coarser octree than the default: the same bug, a quicker preview.
            QVERIFY(w_->document()->setParameter("probe_volumes[0].adaptive.min_cell_size", 240.0, &error));
            const size_t placed = placeProbes(w_->document()->project().scene.probeVolumes[0],
                                              w_->document()->terrain().heightfield).validCount();
            QVERIFY(placed > 1000);
            QVERIFY(QTest::qWaitFor([&] { return w_->boundProbeCount() == placed; }, 30000));
            const QString label = w_->findChild<QLabel*>("status.probes")->text();
            QVERIFY2(label.startsWith(QString("%1 probes (draft preview)").arg(placed)), qPrintable(label));
        }
        // A placement error shows beside the setting it names, and lights nothing (placementErrorsShowInTheProbeVolumesDock)
        {
            QString error;
            QVERIFY(w_->document()->setParameter("probe_volumes[0].adaptive.min_cell_size", 0.5, &error));
            auto* message = w_->findChild<QLabel*>("volumes.placementError");
            QVERIFY(message);
            QVERIFY(message->isVisibleTo(w_.get()));
            QVERIFY2(message->text().contains("occupancy grid") && message->text().contains("adaptive.min_cell_size"),
                     qPrintable(message->text()));
            QVERIFY(w_->statusBar()->currentMessage().contains("occupancy grid"));
            auto* form = qobject_cast<QFormLayout*>(rowOf(w_->findChild<QWidget*>("param.volume.adaptive.min_cell_size"))->parentWidget()->layout());
            QVERIFY(form);
            auto* minLabel = qobject_cast<QLabel*>(form->labelForField(rowOf(w_->findChild<QWidget*>("param.volume.adaptive.min_cell_size"))));
            auto* maxLabel = qobject_cast<QLabel*>(form->labelForField(rowOf(w_->findChild<QWidget*>("param.volume.adaptive.max_cell_size"))));
            QVERIFY(minLabel && maxLabel);
            QVERIFY(minLabel->styleSheet().contains("color"));
            QVERIFY(maxLabel->styleSheet().isEmpty());
            QVERIFY(waitForProbes(*w_, "no preview: placement failed"));
            QCOMPARE(w_->boundProbeCount(), size_t(0));
            w_->findChild<QAction*>("action.undo")->trigger();
            QVERIFY(!message->isVisibleTo(w_.get()));
            QVERIFY(minLabel->styleSheet().isEmpty());
        }
    }

    // The Water dock: presets and the wave list edit water.waves undoably; the amplitude and
    // steepness columns are two faces of one number; Play animates the viewport and Pause stops it.
    void waterDockEditsWavesAndAnimates() {
        auto* dock = w_->findChild<QDockWidget*>("dock.water");
        QVERIFY(dock);
        dock->raise();
        w_->findChild<QCheckBox*>("param.water.enabled")->setChecked(true);
        QVERIFY(w_->document()->project().scene.water.enabled);
        auto* table = w_->findChild<QTableWidget*>("water.waves");
        auto* preset = w_->findChild<QComboBox*>("water.preset");
        QVERIFY(table && preset);
        const nlohmann::json before = w_->document()->value("water.waves");
        const int choppy = preset->findText("choppy lake");
        QVERIFY(choppy > 0);
        emit preset->activated(choppy);
        const size_t choppyWaves = water::wavePreset("choppy lake").size();
        QCOMPARE(w_->document()->project().scene.water.waves.size(), choppyWaves);
        QCOMPARE(table->rowCount(), int(choppyWaves));
        QCOMPARE(preset->currentIndex(), 0);
        w_->findChild<QAction*>("action.undo")->trigger();
        QCOMPARE(w_->document()->value("water.waves"), before);
        w_->findChild<QAction*>("action.redo")->trigger();
        QCOMPARE(table->rowCount(), int(choppyWaves));

        // Add copies the selected wave turned by 30 degrees; Remove takes it away again.
        table->selectRow(0);
        w_->findChild<QPushButton*>("water.addWave")->click();
        QCOMPARE(table->rowCount(), int(choppyWaves) + 1);
        const auto& waves = w_->document()->project().scene.water.waves;
        QCOMPARE(std::fmod(waves.back().directionDeg - waves.front().directionDeg + 360.0, 360.0), 30.0);
        w_->findChild<QPushButton*>("water.removeWave")->click();
        QCOMPARE(table->rowCount(), int(choppyWaves));

        // Editing the amplitude makes it the wave's own number; the steepness column follows.
        table->item(0, 2)->setText("0.25");
        QCOMPARE(*w_->document()->project().scene.water.waves[0].amplitude, 0.25);
        QVERIFY(!w_->document()->project().scene.water.waves[0].steepness);
        const double k = 2.0 * std::numbers::pi / w_->document()->project().scene.water.waves[0].wavelength;
        QCOMPARE(table->item(0, 3)->text().toDouble(), QString::number(0.25 * k, 'g', 4).toDouble());
        // A wave set that breaks the steepness rule is refused and the table shows the project.
        table->item(0, 3)->setText("1.0");
        QVERIFY(!w_->document()->project().scene.water.waves[0].steepness);
        QCOMPARE(table->item(0, 2)->text().toDouble(), 0.25);

        // Up and Down reorder.
        const double first = w_->document()->project().scene.water.waves[0].wavelength;
        table->selectRow(0);
        w_->findChild<QPushButton*>("water.waveDown")->click();
        QCOMPARE(w_->document()->project().scene.water.waves[1].wavelength, first);

        // The time slider sets the viewport's time; Play advances it; Pause stops it.
        auto* slider = w_->findChild<QSlider*>("water.time");
        slider->setValue(100);
        QCOMPARE(w_->viewport()->waterTime(), 10.0);
        auto* play = w_->findChild<QPushButton*>("water.play");
        play->click();
        QTRY_VERIFY_WITH_TIMEOUT(w_->viewport()->waterTime() > 10.2, 3000);
        play->click();
        const double stopped = w_->viewport()->waterTime();
        QTest::qWait(300);
        QCOMPARE(w_->viewport()->waterTime(), stopped);
        // Paused: once a frame requested before the pause has landed (slow under load), no
        // frame without a change. A viewport that kept animating never has a quiet 300 ms.
        QVERIFY(settlesQuiet(w_->viewport()));
        w_->findChild<QCheckBox*>("param.water.enabled")->setChecked(false);
    }

    void reflectionProbesDockPreviewsInspectsAndPicks() {
        auto* dock = w_->findChild<QDockWidget*>("dock.reflectionProbes");
        QVERIFY(dock);
        dock->raise();
        QString error;
        // Small cubes keep the preview quick.
        QVERIFY(w_->document()->setParameter("reflection_probes.resolution", 8, &error));
        auto* enabled = w_->findChild<QCheckBox*>("param.reflection_probes.enabled");
        QVERIFY(enabled);
        auto* selector = w_->findChild<QComboBox*>("viewport.debugView");
        selector->setCurrentIndex(selector->findData(kViewReflectionWeight));
        w_->viewport()->renderNow();
        const RenderedImage off = w_->viewport()->grabImage();
        double offMean = 0;
        for (size_t i = 0; i < size_t(off.width) * off.height; ++i) offMean += off.rgba[i * 4];
        QCOMPARE(offMean, 0.0);  // no probes: no weight anywhere

        enabled->setChecked(true);
        auto* status = w_->findChild<QLabel*>("reflection.status");
        QTRY_VERIFY_WITH_TIMEOUT(status->text().startsWith("16 probes (draft preview)"), 30000);
        QVERIFY(w_->findChild<QSpinBox*>("param.reflection_probes.resolution")->isVisible());
        // The blend weight covers the terrain once the preview lands.
        QTRY_VERIFY_WITH_TIMEOUT([&] {
            const RenderedImage on = w_->viewport()->grabImage();
            size_t lit = 0;
            for (size_t i = 0; i < size_t(on.width) * on.height; ++i) lit += on.rgba[i * 4] > 0.99f;
            return lit > size_t(on.width) * on.height / 10;
        }(), 10000);
        // Strength applies live: 0 leaves no weight.
        auto* strength = w_->findChild<QDoubleSpinBox*>("param.reflection_probes.strength");
        QVERIFY(strength);
        strength->setValue(0.0);
        w_->viewport()->renderNow();
        const RenderedImage none = w_->viewport()->grabImage();
        float most = 0;
        for (size_t i = 0; i < size_t(none.width) * none.height; ++i) most = std::max(most, none.rgba[i * 4]);
        QCOMPARE(most, 0.0f);
        w_->findChild<QAction*>("action.undo")->trigger();
        QCOMPARE(w_->document()->project().scene.reflectionProbes.strength, 1.0);

        // The inspector: probe 9 is past the simvx records' first 8; its cube cross is drawn.
        auto* probe = w_->findChild<QSpinBox*>("reflection.probe");
        auto* inSimvx = w_->findChild<QCheckBox*>("reflection.inSimvx");
        QVERIFY(probe && inSimvx);
        QCOMPARE(probe->maximum(), 15);
        probe->setValue(9);
        QVERIFY(!inSimvx->isChecked());
        QVERIFY(w_->findChild<QLabel*>("reflection.probeInfo")->text().startsWith("id 9 at ("));
        auto* panel = w_->findChild<ReflectionPanel*>();
        QCOMPARE(panel->crossImage().size(), QSize(4 * 48, 3 * 48));
        {
            // The whole cross comes into view in its dock, not cut at the dock's bottom.
            auto* dock = w_->findChild<QDockWidget*>("dock.reflectionProbes");
            dock->raise();
            auto* image = w_->findChild<QLabel*>("reflection.inspector");
            auto* area = dock->findChild<QScrollArea*>();
            QVERIFY(image && area);
            // The page grows to hold the cross (it kept the height it had with the label empty),
            // and scrolled to the cross's bottom edge, the whole cross is in view.
            auto bottom = [&] { return image->mapTo(area->widget(), QPoint(0, image->height())).y(); };
            QTRY_VERIFY(image->height() >= 3 * 48 &&
                        area->verticalScrollBar()->maximum() >= bottom() - area->viewport()->height());
            // Scrolled again until the layout holds still: the page may still grow after a scroll.
            auto shownRect = [&] { return QRect(image->mapTo(area->viewport(), QPoint(0, 0)), image->size()); };
            auto pixmapRect = [&] { return QRect(shownRect().topLeft() + image->contentsRect().topLeft(), image->pixmap().size()); };
            QTRY_VERIFY_WITH_TIMEOUT(
                (area->verticalScrollBar()->setValue(bottom() - area->viewport()->height()),
                 area->viewport()->rect().contains(pixmapRect())),
                5000);
            const QRect shown = shownRect(), pixmap = pixmapRect();
            QVERIFY(w_->grab().save(QString::fromStdString((kOut / "reflection_inspector.png").string())));
            QVERIFY2(image->height() >= 3 * 48 && area->viewport()->rect().contains(pixmap),
                     qPrintable(QString("label %1x%2 at %3,%4 in a %5x%6 view").arg(image->width()).arg(image->height())
                                    .arg(shown.x()).arg(shown.y()).arg(area->viewport()->width()).arg(area->viewport()->height())));
        }
        // The +Y face (the sky, above) is brighter than the -Y face (the ground, below).
        const QColor up = panel->crossImage().pixelColor(48 + 24, 24), down = panel->crossImage().pixelColor(48 + 24, 2 * 48 + 24);
        QVERIFY2(up.lightness() > down.lightness(), qPrintable(QString("%1 vs %2").arg(up.lightness()).arg(down.lightness())));
        // Swapping probe 0 out of the records and 9 in: two undoable edits of the subset.
        probe->setValue(0);
        QVERIFY(inSimvx->isChecked());
        inSimvx->setChecked(false);
        QCOMPARE(w_->document()->project().scene.reflectionProbes.simvxSubset, (std::vector<int>{1, 2, 3, 4, 5, 6, 7}));
        probe->setValue(9);
        inSimvx->setChecked(true);
        QCOMPARE(w_->document()->project().scene.reflectionProbes.simvxSubset, (std::vector<int>{1, 2, 3, 4, 5, 6, 7, 9}));
        w_->findChild<QAction*>("action.undo")->trigger();
        w_->findChild<QAction*>("action.undo")->trigger();
        QVERIFY(w_->document()->project().scene.reflectionProbes.simvxSubset.empty());
        QVERIFY(!inSimvx->isChecked());

        // A click on a probe's marker inspects it.
        const Heightfield& hf = w_->document()->terrain().heightfield;
        const float extent = std::max({hf.maxX() - hf.minX(), hf.maxZ() - hf.minZ(), hf.maxHeight() - hf.minHeight(), 1.0f});
        const OrbitCamera& camera = w_->viewport()->camera();
        const glm::mat4 vp = camera.viewProjection(float(w_->viewport()->width()) / float(w_->viewport()->height()), extent);
        ReflectionProbeSettings rs = w_->document()->project().scene.reflectionProbes;
        const glm::vec3 target = placeReflectionProbes(rs, hf).positions[5];
        const glm::vec4 c = vp * glm::vec4(target, 1.0f);
        const QPoint at(int((c.x / c.w * 0.5f + 0.5f) * float(w_->viewport()->width())),
                        int((c.y / c.w * 0.5f + 0.5f) * float(w_->viewport()->height())));
        QCOMPARE(w_->reflectionProbeAt(at), 5);
        QTest::mouseClick(w_->viewport(), Qt::LeftButton, Qt::NoModifier, at);
        QTRY_COMPARE(probe->value(), 5);
        selector->setCurrentIndex(selector->findData(kViewBeauty));
        enabled->setChecked(false);
        QTRY_VERIFY_WITH_TIMEOUT(status->text() == "Reflection probes are off.", 5000);
    }

    // The diffuse-probe inspector: a click on a probe marker shows that probe of the bound
    // preview, its numbers the bound coefficients themselves, its ball lit from the sky above.
    // Volumes in the viewport: the bounds are drawn, a click on an edge selects the volume, a drag
    // of a handle edits it live (the dock shows the value while the pointer moves) and lands as
    // one undo step with a human label; Escape cancels a drag; the water level and the sun drag
    // the same way.
    void boundsAndHandlesEditVolumes() {
        ViewportGizmos* gizmos = w_->gizmos();
        ViewportWindow* vp = w_->viewport();
        QVERIFY(gizmos);
        QVERIFY(w_->findChild<QAction*>("viewport.bounds.probeVolumes")->isChecked());
        const QSizeF size(vp->width(), vp->height());
        auto screen = [&](const glm::vec3& p) {
            const auto at = ScreenProjection(vp->camera(), size, w_->document()->terrain().heightfield).toScreen(p);
            return at ? at->toPoint() : QPoint(-1, -1);
        };
        auto volumeBounds = [&] {
            for (const VolumeBounds& b : gizmos->bounds(vp->camera()))
                if (b.kind == BoundsKind::ProbeVolume) return b;
            return VolumeBounds{};
        };
        const VolumeBounds box = volumeBounds();
        QCOMPARE(QString::fromStdString(box.name), QString("volume 'probes'"));

        // Drawn: the edge's pixel differs with the bounds shown and hidden.
        const glm::vec3 edgePoint(0.5f * (box.min.x + box.max.x), box.max.y, box.max.z);
        const QPoint edge = screen(edgePoint);
        QVERIFY(QRect(QPoint(0, 0), vp->size()).contains(edge));
        const RenderedImage shown = vp->grabImage(true);
        w_->findChild<QAction*>("viewport.bounds.probeVolumes")->setChecked(false);
        const RenderedImage hidden = vp->grabImage(true);
        w_->findChild<QAction*>("viewport.bounds.probeVolumes")->setChecked(true);
        const qreal dpr = vp->devicePixelRatio();
        double most = 0.0;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const size_t i = (size_t(int(edge.y() * dpr) + dy) * shown.width + size_t(int(edge.x() * dpr) + dx)) * 4;
                most = std::max(most, double(std::abs(shown.rgba[i + 2] - hidden.rgba[i + 2])));
            }
        QVERIFY2(most > 0.2, qPrintable(QString("edge pixel changed by %1").arg(most)));

        // A click on the edge selects the volume.
        QTest::mouseClick(vp, Qt::LeftButton, Qt::NoModifier, edge);
        QTRY_VERIFY(gizmos->selected().has_value());
        QCOMPARE(gizmos->selected()->kind, BoundsKind::ProbeVolume);
        QVERIFY(w_->statusBar()->currentMessage().startsWith("volume 'probes' selected"));

        // Drag the move handle: live, then one undo step.
        QUndoStack* undo = w_->document()->undoStack();
        const int steps = undo->count();
        Handle move;
        for (const Handle& h : gizmos->handles(vp->camera()))
            if (h.role == HandleRole::Move) move = h;
        const QPoint from = screen(move.at), to = from + QPoint(60, 25);
        QTest::mousePress(vp, Qt::LeftButton, Qt::NoModifier, from);
        QVERIFY(vp->grabbing());
        for (int i = 1; i <= 6; ++i) QTest::mouseMove(vp, from + (to - from) * i / 6);
        QTRY_VERIFY(!w_->document()->value("probe_volumes[0].origin").is_null());
        const nlohmann::json live = w_->document()->value("probe_volumes[0].origin");
        auto* originX = w_->findChild<QDoubleSpinBox*>("param.volume.origin.0");
        QVERIFY(originX);
        QCOMPARE(originX->value(), live[0].get<double>());  // the dock follows the drag
        QCOMPARE(undo->count(), steps);                    // nothing on the stack yet
        QTest::mouseRelease(vp, Qt::LeftButton, Qt::NoModifier, to);
        QCOMPARE(undo->count(), steps + 1);
        QCOMPARE(undo->undoText(), QString("Move volume 'probes'"));
        // The handle ends under the pointer.
        Handle moved;
        for (const Handle& h : gizmos->handles(vp->camera()))
            if (h.role == HandleRole::Move) moved = h;
        const QPoint landed = screen(moved.at);
        QVERIFY2((landed - to).manhattanLength() <= 3, qPrintable(QString("handle at %1,%2, pointer at %3,%4")
                                                                      .arg(landed.x()).arg(landed.y()).arg(to.x()).arg(to.y())));
        undo->undo();
        QVERIFY(w_->document()->value("probe_volumes[0].origin").is_null());
        QCOMPARE(volumeBounds(), box);

        // The height handle; Escape puts it back and leaves no step.
        Handle height;
        for (const Handle& h : gizmos->handles(vp->camera()))
            if (h.role == HandleRole::Height) height = h;
        const double offset = w_->document()->value("probe_volumes[0].height_offset").get<double>();
        const QPoint top = screen(height.at);
        QTest::mousePress(vp, Qt::LeftButton, Qt::NoModifier, top);
        for (int i = 1; i <= 4; ++i) QTest::mouseMove(vp, top - QPoint(0, 10 * i));
        QTRY_VERIFY(w_->document()->value("probe_volumes[0].height_offset").get<double>() > offset + 1.0);
        QTest::keyClick(vp, Qt::Key_Escape);
        QCOMPARE(w_->document()->value("probe_volumes[0].height_offset").get<double>(), offset);
        QTest::mouseRelease(vp, Qt::LeftButton, Qt::NoModifier, top - QPoint(0, 40));
        QCOMPARE(undo->count(), steps + 1);  // the undone move is still there to redo; nothing new
        QCOMPARE(undo->index(), steps);

        // The water level: select the water's outline (the probe volume's bounds, which share the
        // footprint's edges, hidden), drag its handle up.
        w_->findChild<QAction*>("viewport.bounds.probeVolumes")->setChecked(false);
        QVERIFY(!gizmos->selected());
        QString error;
        QVERIFY(w_->document()->setParameters({{"water.enabled", true}, {"water.level", 500.0}}, &error));
        VolumeBounds water;
        for (const VolumeBounds& b : gizmos->bounds(vp->camera()))
            if (b.kind == BoundsKind::Water) water = b;
        QCOMPARE(water.min.y, 500.0f);
        // Right on the edge: the water, even where a probe marker lies within a few pixels.
        const QPoint shore = screen(glm::vec3(water.min.x, 500.0f, water.min.z + 3.5f / 7.0f * (water.max.z - water.min.z)));
        QVERIFY(QRect(QPoint(0, 0), vp->size()).contains(shore));
        QTest::mouseClick(vp, Qt::LeftButton, Qt::NoModifier, shore);
        QTRY_VERIFY(gizmos->selected() && gizmos->selected()->kind == BoundsKind::Water);
        const QPoint level = screen(gizmos->handles(vp->camera()).front().at);
        QTest::mousePress(vp, Qt::LeftButton, Qt::NoModifier, level);
        for (int i = 1; i <= 4; ++i) QTest::mouseMove(vp, level - QPoint(0, 8 * i));
        QTest::mouseRelease(vp, Qt::LeftButton, Qt::NoModifier, level - QPoint(0, 32));
        QCOMPARE(undo->undoText(), QString("Set the water level"));
        QVERIFY(w_->document()->value("water.level").get<double>() > 500.0);
        // The dock shows it to its one decimal.
        QVERIFY(std::abs(w_->findChild<QDoubleSpinBox*>("param.water.level")->value() -
                         w_->document()->value("water.level").get<double>()) <= 0.05 + 1e-9);

        // The sun: its point, dragged, turns azimuth and elevation.
        VolumeBounds sun;
        for (const VolumeBounds& b : gizmos->bounds(vp->camera()))
            if (b.kind == BoundsKind::Sun) sun = b;
        QTest::mouseClick(vp, Qt::LeftButton, Qt::NoModifier, screen(sun.min));
        QTRY_VERIFY(gizmos->selected() && gizmos->selected()->kind == BoundsKind::Sun);
        // Zoomed out after the selection, the sun's point stands elsewhere; its handle is grabbed there.
        QTest::keyClick(vp, Qt::Key_Minus);
        for (const VolumeBounds& b : gizmos->bounds(vp->camera()))
            if (b.kind == BoundsKind::Sun) sun = b;
        const QPoint sunAt = screen(sun.min);
        const double azimuth = w_->document()->value("sun.azimuth_deg").get<double>();
        QTest::mousePress(vp, Qt::LeftButton, Qt::NoModifier, sunAt);
        QVERIFY(vp->grabbing());
        for (int i = 1; i <= 5; ++i) QTest::mouseMove(vp, sunAt + QPoint(8 * i, 0));
        QTest::mouseRelease(vp, Qt::LeftButton, Qt::NoModifier, sunAt + QPoint(40, 0));
        QCOMPARE(undo->undoText(), QString("Move the sun"));
        QVERIFY(std::abs(w_->document()->value("sun.azimuth_deg").get<double>() - azimuth) > 1.0);
        // A sun placed by a date and a time moves along its day: the drag sets the local time.
        QVERIFY(w_->document()->setParameters({{"sun.mode", "date_time"}, {"sun.date", "2026-06-21"}, {"sun.time_h", 9.0}},
                                              &error));
        for (const VolumeBounds& b : gizmos->bounds(vp->camera()))
            if (b.kind == BoundsKind::Sun) sun = b;
        const QPoint morning = screen(sun.min);
        QTest::mouseClick(vp, Qt::LeftButton, Qt::NoModifier, morning);
        QTRY_VERIFY(gizmos->selected() && gizmos->selected()->kind == BoundsKind::Sun);
        QTest::mousePress(vp, Qt::LeftButton, Qt::NoModifier, morning);
        for (int i = 1; i <= 5; ++i) QTest::mouseMove(vp, morning + QPoint(8 * i, -6 * i));
        QTest::mouseRelease(vp, Qt::LeftButton, Qt::NoModifier, morning + QPoint(40, -30));
        QCOMPARE(undo->undoText(), QString("Set the time of day"));
        QVERIFY(std::abs(w_->document()->value("sun.time_h").get<double>() - 9.0) >= 0.25);
        QTest::qWait(200);
        QVERIFY(w_->screen()->grabWindow(0, w_->x(), w_->y(), w_->frameGeometry().width(), w_->frameGeometry().height())
                    .save(QString::fromStdString((kOut / "viewport_bounds.png").string())));
    }

    // A whole session as a user drives it: import a DEM, select the probe volume in the viewport
    // and resize it by a handle, place the sun by a date and a time, bake, inspect a probe of the
    // bake, then undo everything; the baked files say what the session set.
    void aFullSessionFromImportToUndo() {
        ProjectDocument& doc = *w_->document();
        ViewportWindow* vp = w_->viewport();
        ViewportGizmos* gizmos = w_->gizmos();
        const nlohmann::json initialDem = doc.value("terrain.dem");
        quickBakeSettings(doc);
        const int setupSteps = doc.undoStack()->index();

        // Import.
        const fs::path dem = fs::path(TERRALUX_TEST_DATA) / "dem" / "rainier_crop.tif";
        QVERIFY(w_->importDemFile(QString::fromStdString(dem.string())));
        QTRY_VERIFY_WITH_TIMEOUT(!doc.terrainLoading() && doc.value("terrain.dem").get<std::string>().ends_with("rainier_crop.tif"),
                                 30000);
        // The viewport draws the new terrain (Mount Rainier) with its own preview.
        QTRY_VERIFY_WITH_TIMEOUT(w_->probeSource() == "draft preview" && vp->renderer() &&
                                     std::abs(vp->renderer()->heightfield().geo.latitudeDeg - 46.85) < 0.5, 30000);
        const Heightfield& hf = doc.terrain().heightfield;

        // Select the volume by its edge and drag its max corner back by a third of the footprint.
        const QSizeF size(vp->width(), vp->height());
        auto screen = [&](const glm::vec3& p) {
            const auto at = ScreenProjection(vp->camera(), size, doc.terrain().heightfield).toScreen(p);
            return at ? at->toPoint() : QPoint(-1, -1);
        };
        VolumeBounds box;
        for (const VolumeBounds& b : gizmos->bounds(vp->camera()))
            if (b.kind == BoundsKind::ProbeVolume) box = b;
        QTest::mouseClick(vp, Qt::LeftButton, Qt::NoModifier, screen(glm::vec3(0.5f * (box.min.x + box.max.x), box.max.y, box.max.z)));
        QTRY_VERIFY(gizmos->selected() && gizmos->selected()->kind == BoundsKind::ProbeVolume);
        Handle corner;
        for (const Handle& h : gizmos->handles(vp->camera()))
            if (h.role == HandleRole::MaxCorner) corner = h;
        const glm::vec3 goal = corner.at - glm::vec3((box.max.x - box.min.x) / 3.0f, 0.0f, (box.max.z - box.min.z) / 3.0f);
        const QPoint from = screen(corner.at), to = screen(goal);
        QTest::mousePress(vp, Qt::LeftButton, Qt::NoModifier, from);
        for (int i = 1; i <= 8; ++i) QTest::mouseMove(vp, from + (to - from) * i / 8);
        QTest::mouseRelease(vp, Qt::LeftButton, Qt::NoModifier, to);
        QCOMPARE(doc.undoStack()->undoText(), QString("Resize volume 'probes'"));
        const nlohmann::json origin = doc.value("probe_volumes[0].origin"), spacing = doc.value("probe_volumes[0].spacing");
        QVERIFY(origin.is_array() && spacing.is_array());
        const double sx = spacing[0].get<double>(), sz = spacing[1].get<double>();
        const double autoStep = (hf.maxX() - hf.minX()) / 7.0;
        QVERIFY2(sx < 0.8 * autoStep && sx > 0.55 * autoStep, qPrintable(QString("%1 vs %2").arg(sx).arg(autoStep)));

        // The sun by a date and a time, through the Sun & Sky dock.
        w_->findChild<QDockWidget*>("dock.sunSky")->raise();
        w_->findChild<QComboBox*>("param.sun.mode")->setCurrentText("date_time");
        auto* date = w_->findChild<QLineEdit*>("param.sun.date");
        date->setText("2026-08-14");
        QMetaObject::invokeMethod(date, "editingFinished");
        w_->findChild<QSlider*>("param.sun.time_h.slider")->setValue(375);  // 09:00
        QCOMPARE(doc.project().scene.sun.timeH, 9.0);
        QCOMPARE(doc.project().scene.sun.date, std::string("2026-08-14"));

        // An evening scenario of the same day: its own time of day, the same probes.
        QTest::mouseClick(w_->findChild<QPushButton*>("scenarios.add"), Qt::LeftButton);
        QCOMPARE(doc.undoStack()->undoText(), QString("Add scenario 'scenario-1'"));
        w_->findChild<QSlider*>("param.scenario.sun.time_h.slider")->setValue(750);  // 18:00
        QCOMPARE(doc.project().scene.scenarios[0].sun.timeH, 18.0);
        QCOMPARE(doc.project().scene.scenarios[0].sun.date, std::string("2026-08-14"));

        // Bake, and read what it wrote.
        w_->startBake();
        QVERIFY(QTest::qWaitFor([&] { return !w_->bakes()->running() && w_->probeSource() == "last bake"; }, 90000));
        const fs::path out = kOut / "bake";
        std::ifstream reportFile(out / "bake_report.json");
        const nlohmann::json report = nlohmann::json::parse(reportFile);
        QCOMPARE(report["sun"]["date"].get<std::string>(), std::string("2026-08-14"));
        QCOMPARE(report["sun"]["time_h"].get<double>(), 9.0);
        QCOMPARE(report["scenarios"][0]["name"].get<std::string>(), std::string("scenario-1"));
        QVERIFY(fs::exists(out / "scenarios" / "probes.scenario-1.shprobe"));
        std::ifstream gltfFile(out / "scene.gltf");
        const nlohmann::json gltf = nlohmann::json::parse(gltfFile);
        const nlohmann::json& listed = gltf["scenes"][0]["extensions"]["TERRALUX_lighting"]["scenarios"];
        QCOMPARE(listed.size(), size_t(2));
        QCOMPARE(listed[1]["sun"]["time_h"].get<double>(), 18.0);
        QCOMPARE(listed[1]["shProbePaths"][0].get<std::string>(), std::string("scenarios/probes.scenario-1.shprobe"));
        std::ifstream sidecar(out / "sh_coeffs" / "probes.probes.json");
        const nlohmann::json probes = nlohmann::json::parse(sidecar);
        const std::vector<double> positions = probes["positions"].get<std::vector<double>>();
        QCOMPARE(positions.size(), size_t(64 * 3));
        QVERIFY(std::abs(positions[0] - origin[0].get<double>()) < 0.01);
        QVERIFY(std::abs(positions[2] - origin[1].get<double>()) < 0.01);
        QVERIFY(std::abs(positions[63 * 3] - (origin[0].get<double>() + 7.0 * sx)) < 0.05);
        QVERIFY(std::abs(positions[63 * 3 + 2] - (origin[1].get<double>() + 7.0 * sz)) < 0.05);

        // Inspect a probe of the bake by its marker.
        const auto volumes = vp->renderer()->boundVolumes();
        QVERIFY(volumes->size() == 1 && volumes->front().diagnostics);
        const int target = 2 * 8 + 5;
        const QPoint marker = screen(volumes->front().diagnostics->positions[size_t(target)]);
        QTest::mouseClick(vp, Qt::LeftButton, Qt::NoModifier, marker);
        QTRY_COMPARE(w_->findChild<QSpinBox*>("probeInspector.probe")->value(), target);
        QVERIFY(w_->findChild<QLabel*>("probeInspector.status")->text().contains("last bake"));

        // Undo everything this session did: the sample, the auto grid and the manual sun again.
        while (doc.undoStack()->index() > setupSteps) doc.undoStack()->undo();
        QTRY_VERIFY_WITH_TIMEOUT(!doc.terrainLoading(), 30000);
        QCOMPARE(doc.value("terrain.dem"), initialDem);
        QVERIFY(doc.value("probe_volumes[0].origin").is_null() && doc.value("probe_volumes[0].spacing").is_null());
        QCOMPARE(doc.project().scene.sun.mode, SunMode::Manual);
        QVERIFY(doc.project().scene.scenarios.empty());
        QVERIFY(std::abs(doc.terrain().heightfield.geo.latitudeDeg - 34.34) < 0.01);
    }

    // Lighting scenarios: added, edited and renamed in the Sun & Sky dock, each one undo step; the
    // viewport shows the one selected and blends toward another from its toolbar.
    void scenariosAreEditedShownAndBlended() {
        ProjectDocument& doc = *w_->document();
        ViewportWindow* vp = w_->viewport();
        const int start = doc.undoStack()->index();
        auto* bar = w_->findChild<QToolBar*>("toolbar.scenarios");
        auto* list = w_->findChild<QListWidget*>("scenarios.list");
        QVERIFY(bar && list);
        QVERIFY(!bar->isVisible());
        QCOMPARE(list->count(), 1);
        const RenderedImage defaultFrame = vp->grabImage();

        w_->findChild<QDockWidget*>("dock.sunSky")->raise();
        QTest::mouseClick(w_->findChild<QPushButton*>("scenarios.add"), Qt::LeftButton);
        QCOMPARE(doc.undoStack()->undoText(), QString("Add scenario 'scenario-1'"));
        QCOMPARE(doc.project().scene.scenarios.size(), size_t(1));
        QCOMPARE(list->count(), 2);
        QCOMPARE(list->currentItem()->data(Qt::UserRole).toString(), QString("scenario-1"));
        QVERIFY(bar->isVisible());
        // A copy of the default's light, shown in the viewport while it is edited.
        QCOMPARE(doc.project().scene.scenarios[0].sun.elevationDeg, doc.project().scene.sun.elevationDeg);
        QCOMPARE(w_->scenarioView().a, std::string("scenario-1"));
        auto* elevation = w_->findChild<QDoubleSpinBox*>("param.scenario.sun.elevation_deg");
        QVERIFY(elevation && elevation->isVisible());
        QVERIFY(!w_->findChild<QDoubleSpinBox*>("param.sun.elevation_deg")->isVisible());
        elevation->setValue(8.0);
        QCOMPARE(doc.project().scene.scenarios[0].sun.elevationDeg, 8.0);
        QCOMPARE(doc.project().scene.sun.elevationDeg, 35.0);
        QCOMPARE(doc.undoStack()->undoText(), QString("Set Sun elevation of scenario 'scenario-1'"));
        w_->findChild<QDoubleSpinBox*>("param.scenario.sun.azimuth_deg")->setValue(260.0);
        // The scenario's rows hide as its own sky mode says, not the default's.
        auto* scenarioDock = w_->findChild<QDockWidget*>("dock.sunSky");
        auto rowShown = [&](const char* name) {
            QWidget* w = w_->findChild<QWidget*>(name);
            return w && rowOf(w)->isVisibleTo(scenarioDock);
        };
        QVERIFY(rowShown("param.scenario.sky.color") && !rowShown("param.scenario.sky.turbidity"));
        w_->findChild<QComboBox*>("param.scenario.sky.mode")->setCurrentText("physical");
        QCOMPARE(doc.project().scene.scenarios[0].sky.mode, SkyMode::Physical);
        QCOMPARE(doc.project().scene.sky.mode, SkyMode::Uniform);
        QVERIFY(!rowShown("param.scenario.sky.color") && rowShown("param.scenario.sky.turbidity"));
        doc.undoStack()->undo();
        QCOMPARE(doc.project().scene.scenarios[0].sky.mode, SkyMode::Uniform);
        QTRY_VERIFY_WITH_TIMEOUT(w_->probeSource() == "draft preview" &&
                                     w_->findChild<QLabel*>("status.probes")->text().contains("scenario 'scenario-1'"),
                                 30000);
        QTRY_VERIFY_WITH_TIMEOUT(test::compareImages(vp->grabImage().rgba, defaultFrame.rgba, defaultFrame.width,
                                                     defaultFrame.height).meanAbs > 0.02, 20000);

        // The sun handle is the shown scenario's: its drag moves that scenario's sun, not the project's.
        {
            ViewportGizmos* gizmos = w_->gizmos();
            const QSizeF size(vp->width(), vp->height());
            auto screen = [&](const glm::vec3& p) {
                const auto at = ScreenProjection(vp->camera(), size, doc.terrain().heightfield).toScreen(p);
                return at ? at->toPoint() : QPoint(-1, -1);
            };
            VolumeBounds sun;
            for (const VolumeBounds& b : gizmos->bounds(vp->camera()))
                if (b.kind == BoundsKind::Sun) sun = b;
            const SunAngles shown = sunAnglesOf(scenarioScene(doc.project().scene, "scenario-1"), doc.terrain().heightfield);
            const glm::vec3 toward = glm::normalize(sun.min - vp->camera().target);
            QVERIFY(std::abs(std::asin(double(toward.y)) * 180.0 / std::numbers::pi - shown.elevationDeg) < 0.5);
            const QPoint at = screen(sun.min);
            QTest::mouseClick(vp, Qt::LeftButton, Qt::NoModifier, at);
            QTRY_VERIFY(gizmos->selected() && gizmos->selected()->kind == BoundsKind::Sun);
            // Toward the view's target on screen: the point crosses the sphere's near side.
            const QPoint centre = screen(vp->camera().target), to = at + (centre - at) / 2;
            QSignalSpy refusals(gizmos, &ViewportGizmos::rejected);
            QTest::mousePress(vp, Qt::LeftButton, Qt::NoModifier, at);
            QVERIFY(vp->grabbing());
            for (int i = 1; i <= 8; ++i) QTest::mouseMove(vp, at + (to - at) * i / 8);
            QCOMPARE(refusals.count(), 0);
            QTest::mouseRelease(vp, Qt::LeftButton, Qt::NoModifier, to);
            QCOMPARE(doc.undoStack()->undoText(), QString("Move the sun"));
            QVERIFY(std::abs(doc.project().scene.scenarios[0].sun.azimuthDeg - 260.0) > 1.0 ||
                    std::abs(doc.project().scene.scenarios[0].sun.elevationDeg - 8.0) > 1.0);
            QCOMPARE(doc.project().scene.sun.azimuthDeg, 135.0);
            QCOMPARE(doc.project().scene.sun.elevationDeg, 35.0);
            doc.undoStack()->undo();
            QCOMPARE(doc.project().scene.scenarios[0].sun.azimuthDeg, 260.0);
            QCOMPARE(doc.project().scene.scenarios[0].sun.elevationDeg, 8.0);
        }

        // Rename: a name the rules refuse is named and the old one stays.
        auto* name = w_->findChild<QLineEdit*>("scenarios.name");
        name->setText("default");
        QMetaObject::invokeMethod(name, "editingFinished");
        QVERIFY(w_->findChild<QLabel*>("scenarios.error")->text().contains("must be unique among scenarios and not \"default\""));
        QCOMPARE(name->text(), QString("scenario-1"));
        name->setText("dusk");
        QMetaObject::invokeMethod(name, "editingFinished");
        QCOMPARE(doc.project().scene.scenarios[0].name, std::string("dusk"));
        QCOMPARE(doc.undoStack()->undoText(), QString("Rename scenario 'scenario-1' to 'dusk'"));
        QCOMPARE(w_->scenarioView().a, std::string("dusk"));

        // The toolbar: default blended halfway toward dusk.
        w_->findChild<QComboBox*>("viewport.scenario")->setCurrentText("default");
        QCOMPARE(w_->scenarioView().a, std::string("default"));
        QCOMPARE(list->currentItem()->data(Qt::UserRole).toString(), QString("default"));
        QVERIFY(w_->findChild<QDoubleSpinBox*>("param.sun.elevation_deg")->isVisible());
        w_->findChild<QComboBox*>("viewport.scenarioTo")->setCurrentText("dusk");
        w_->findChild<QSlider*>("viewport.scenarioBlend")->setValue(50);
        QVERIFY(w_->scenarioView().blends());
        QTRY_VERIFY_WITH_TIMEOUT(w_->probeSource() == "draft preview" &&
                                     w_->findChild<QLabel*>("status.probes")->text().contains("default → dusk 50 %"),
                                 30000);
        QVERIFY(w_->findChild<QDockWidget*>("dock.sunSky")->grab().save(QString::fromStdString((kOut / "scenarios_dock.png").string())));
        QTest::qWait(100);
        QVERIFY(w_->screen()->grabWindow(0, w_->x(), w_->y(), w_->frameGeometry().width(), w_->frameGeometry().height())
                    .save(QString::fromStdString((kOut / "scenarios_window.png").string())));
        // Back to the default alone: the frame it drew before.
        w_->findChild<QSlider*>("viewport.scenarioBlend")->setValue(0);
        QTRY_VERIFY_WITH_TIMEOUT(test::compareImages(vp->grabImage().rgba, defaultFrame.rgba, defaultFrame.width,
                                                     defaultFrame.height).maxAbs <= 1.0 / 255.0, 30000);

        // Remove, then undo everything: no scenario, no toolbar.
        list->setCurrentRow(1);
        QTest::mouseClick(w_->findChild<QPushButton*>("scenarios.remove"), Qt::LeftButton);
        QCOMPARE(doc.undoStack()->undoText(), QString("Remove scenario 'dusk'"));
        QVERIFY(doc.project().scene.scenarios.empty());
        QVERIFY(!bar->isVisible());
        QCOMPARE(w_->scenarioView().a, std::string("default"));
        doc.undoStack()->undo();
        QCOMPARE(doc.project().scene.scenarios.size(), size_t(1));
        while (doc.undoStack()->index() > start) doc.undoStack()->undo();
        QVERIFY(doc.project().scene.scenarios.empty());
        QCOMPARE(list->count(), 1);
    }

    void probeInspectorShowsAClickedProbe() {
        auto* group = w_->findChild<QWidget*>("probeInspector.group");
        auto* probe = w_->findChild<QSpinBox*>("probeInspector.probe");
        auto* info = w_->findChild<QLabel*>("probeInspector.info");
        auto* inspector = w_->findChild<ProbeInspector*>();
        QVERIFY(group && probe && info && inspector);
        QVERIFY(w_->findChild<QLabel*>("probeInspector.status")->text().startsWith("64 probes (draft preview)"));
        QCOMPARE(probe->maximum(), 63);

        const auto volumes = w_->viewport()->renderer()->boundVolumes();
        QCOMPARE(volumes->size(), size_t(1));
        const GpuProbeVolume& g = volumes->front();
        QVERIFY(g.diagnostics && g.diagnostics->standardError.size() == 64);
        const Heightfield& hf = w_->document()->terrain().heightfield;
        const float extent = std::max({hf.maxX() - hf.minX(), hf.maxZ() - hf.minZ(), hf.maxHeight() - hf.minHeight(), 1.0f});
        const glm::mat4 vp = w_->viewport()->camera().viewProjection(
            float(w_->viewport()->width()) / float(w_->viewport()->height()), extent);
        // A probe in the middle of the grid, in view.
        const int target = 3 * 8 + 4;
        const glm::vec4 c = vp * glm::vec4(g.diagnostics->positions[size_t(target)], 1.0f);
        const QPoint at(int((c.x / c.w * 0.5f + 0.5f) * float(w_->viewport()->width())),
                        int((c.y / c.w * 0.5f + 0.5f) * float(w_->viewport()->height())));
        QCOMPARE(w_->diffuseProbeAt(at), std::optional(std::pair(0, target)));
        QTest::mouseClick(w_->viewport(), Qt::LeftButton, Qt::NoModifier, at);
        QTRY_COMPARE(probe->value(), target);
        QVERIFY(w_->findChild<QDockWidget*>("dock.probeVolumes")->isVisible());

        // The numbers are the bound probe's: its position, its standard error, its DC term.
        const glm::vec3 p = g.diagnostics->positions[size_t(target)];
        const QString text = info->text();
        QVERIFY2(text.startsWith(QString("at (%1, ").arg(p.x, 0, 'f', 1)), qPrintable(text));
        QVERIFY2(text.contains(QString("standard error %1 %").arg(100.0 * g.diagnostics->standardError[size_t(target)], 0, 'f', 2)),
                 qPrintable(text));
        const glm::vec3 dc = g.coeffs[size_t(target)][0];
        QVERIFY2(text.contains(QString("%1 %2 %3").arg(dc.x, 8, 'f', 4).arg(dc.y, 8, 'f', 4).arg(dc.z, 8, 'f', 4)), qPrintable(text));
        QVERIFY2(text.contains("interpolation error within"), qPrintable(text));
        // E up is the irradiance the viewport evaluates for a level surface.
        const glm::vec3 up = probeIrradiance(g, size_t(target), glm::vec3(0, 1, 0));
        QVERIFY(text.contains(QString("E up   %1").arg(up.x, 8, 'f', 4)));
        QVERIFY(up.y > probeIrradiance(g, size_t(target), glm::vec3(0, -1, 0)).y);
        // The ball: its top (sky) brighter than its bottom (ground); grey off the ball.
        const QImage& ball = inspector->ballImage();
        QCOMPARE(ball.size(), QSize(128, 128));
        QVERIFY(QColor(ball.pixel(64, 8)).lightness() > QColor(ball.pixel(64, 120)).lightness());
        QCOMPARE(QColor(ball.pixel(1, 1)), QColor(40, 40, 40));
        for (QWidget* p = group; p; p = p->parentWidget())
            if (auto* scroll = qobject_cast<QScrollArea*>(p)) scroll->ensureWidgetVisible(group);
        QTest::qWait(100);
        QVERIFY(w_->screen()->grabWindow(0, w_->x(), w_->y(), w_->frameGeometry().width(), w_->frameGeometry().height())
                    .save(QString::fromStdString((kOut / "probe_inspector.png").string())));
        QVERIFY(group->grab().save(QString::fromStdString((kOut / "probe_inspector_group.png").string())));
        // A click on the terrain between probes 28 and 29 says which probes light it, and how much.
        const glm::vec3 other = g.diagnostics->positions[size_t(target + 1)];
        const float mx = 0.5f * (p.x + other.x), mz = p.z;
        const glm::vec3 ground(mx, hf.surfaceHeight(mx, mz), mz);
        const glm::vec4 gc = vp * glm::vec4(ground, 1.0f);
        const QPoint onGround(int((gc.x / gc.w * 0.5f + 0.5f) * float(w_->viewport()->width())),
                              int((gc.y / gc.w * 0.5f + 0.5f) * float(w_->viewport()->height())));
        QVERIFY(!w_->diffuseProbeAt(onGround));
        const std::optional<glm::vec3> picked = w_->terrainPointAt(onGround);
        QVERIFY(picked && glm::length(*picked - ground) < 60.0f);  // within about two 30 m cells
        QTest::mouseClick(w_->viewport(), Qt::LeftButton, Qt::NoModifier, onGround);
        auto* point = w_->findChild<QLabel*>("probeInspector.point");
        QTRY_VERIFY(point->isVisibleTo(group));
        const ProbeWeights weights = probeWeightsAt(*volumes, *picked);
        QCOMPARE(weights.volume, 0);
        float total = 0.0f;
        for (const auto& [record, weight] : weights.probes) total += weight;
        QVERIFY(std::abs(total - 1.0f) < 1e-5f);
        std::vector<int> firstTwo{weights.probes[0].first, weights.probes[1].first};
        std::sort(firstTwo.begin(), firstTwo.end());
        QCOMPARE(firstTwo, (std::vector<int>{target, target + 1}));
        QVERIFY(weights.probes[1].second > 0.3f);
        QVERIFY2(point->text().contains(QString("probe %1 × %2").arg(weights.probes[0].first).arg(weights.probes[0].second, 0, 'f', 3)),
                 qPrintable(point->text()));
        QCOMPARE(probe->value(), weights.probes[0].first);  // the heaviest is inspected
        // A marker click afterwards hides the point's line again.
        QTest::mouseClick(w_->viewport(), Qt::LeftButton, Qt::NoModifier, at);
        QTRY_VERIFY(!point->isVisibleTo(group));

        // Exposure follows the viewport's.
        const int before = QColor(ball.pixel(64, 64)).lightness();
        QString error;
        QVERIFY(w_->document()->setParameter("camera.exposure_ev", 2.0, &error));
        QVERIFY(QColor(inspector->ballImage().pixel(64, 64)).lightness() > before);
        w_->document()->undoStack()->undo();
    }

    // Load: a thousand edits through the docks' editors, back to back with no waits. Nothing
    // crashes, the viewport then draws what the command line draws for the final project, undo
    // unwinds to the start, and memory does not grow with the edits.
    // The LPV on while the indirect light leaves it out lights nothing: the dock says so and offers
    // the edit that adds its light; the indirect light asking for an LPV that is off, likewise.
    void lpvDockSaysWhenTheLpvLightsNothing() {
        auto* dock = w_->findChild<QDockWidget*>("dock.lpv");
        QVERIFY(dock);
        dock->raise();
        ProjectDocument* doc = w_->document();
        auto* hint = dock->findChild<QLabel*>("lpv.hint");
        auto* fix = dock->findChild<QPushButton*>("lpv.hintFix");
        QVERIFY(hint && fix);
        // The defaults agree: no LPV, probes.
        QVERIFY(!hint->isVisibleTo(dock));
        auto* enabled = dock->findChild<QCheckBox*>("param.lpv.enabled");
        enabled->setChecked(true);
        QVERIFY(doc->project().scene.lpv.enabled);
        QVERIFY(hint->isVisibleTo(dock) && fix->isVisibleTo(dock));
        QVERIFY(hint->text().contains("adds no light: Indirect light is 'probes'"));
        QCOMPARE(fix->text(), QString("Light with probes and LPV"));
        // The beauty frame's terrain pass reads the LPV's light only once the fix is made.
        const auto terrainReadsLpv = [&] {
            w_->viewport()->renderNow();
            for (const PassInfo& p : w_->viewport()->renderer()->renderer().lastFramePasses())
                if (p.name == "terrain")
                    for (const ResourceUse& u : p.uses)
                        if (u.resource == "lpv-light") return true;
            return false;
        };
        QVERIFY(!terrainReadsLpv());
        fix->click();
        QCOMPARE(doc->project().scene.lighting.indirect, IndirectLighting::Both);
        QVERIFY(!hint->isVisibleTo(dock));
        QVERIFY(QTest::qWaitFor(terrainReadsLpv, 60000));
        // One undoable edit, named in words.
        QCOMPARE(doc->undoStack()->undoText(), QString("Set Indirect light (lighting)"));
        doc->undoStack()->undo();
        QVERIFY(hint->isVisibleTo(dock));
        // Off with the indirect light asking for it: the other way round.
        dock->findChild<QComboBox*>("param.lighting.indirect")->setCurrentText("lpv");
        enabled->setChecked(false);
        QVERIFY(hint->isVisibleTo(dock));
        QVERIFY(hint->text().contains("Indirect light is 'lpv', but Light propagation volumes is off"));
        QCOMPARE(fix->text(), QString("Turn the LPV on"));
        fix->click();
        QVERIFY(doc->project().scene.lpv.enabled);
        QVERIFY(!hint->isVisibleTo(dock));
    }

    // The LPV dock edits every lpv setting and the indirect selector (undoable), names each
    // setting's console variable in its tooltip, and adds, edits and deletes lights.
    void lpvDockEditsSettingsAndLights() {
        auto* dock = w_->findChild<QDockWidget*>("dock.lpv");
        QVERIFY(dock);
        QCOMPARE(dock->windowTitle(), QString("LPV"));
        dock->raise();
        ProjectDocument* doc = w_->document();
        QUndoStack* stack = doc->undoStack();
        const int startIndex = stack->index();
        auto* undo = w_->findChild<QAction*>("action.undo");

        auto* indirect = dock->findChild<QComboBox*>("param.lighting.indirect");
        QVERIFY(indirect);
        QCOMPARE(doc->value("lighting.indirect").get<std::string>(), std::string("probes"));
        indirect->setCurrentText("both");
        QCOMPARE(doc->project().scene.lighting.indirect, IndirectLighting::Both);
        undo->trigger();
        QCOMPARE(doc->project().scene.lighting.indirect, IndirectLighting::Probes);
        QCOMPARE(indirect->currentText(), QString("probes"));
        indirect->setCurrentText("lpv");
        QCOMPARE(doc->project().scene.lighting.indirect, IndirectLighting::Lpv);

        // Off, the rows LPV-on reads are hidden; on, each row shows where the scene reads it.
        auto* enabled = dock->findChild<QCheckBox*>("param.lpv.enabled");
        QVERIFY(enabled);
        QVERIFY(!rowOf(dock->findChild<QWidget*>("param.lpv.size"))->isVisibleTo(dock));
        enabled->setChecked(true);
        QVERIFY(doc->project().scene.lpv.enabled);
        // lpv.size "auto" says what it is on this terrain: the sample's longer side.
        auto* size = dock->findChild<QDoubleSpinBox*>("param.lpv.size");
        QVERIFY(size);
        QCOMPARE(size->text(), QString("terrain side (%1 m)").arg(QLocale().toString(7650.0, 'f', 0)));
        // What hovering shows: the editor's tooltip, or (spin boxes in a row) its row's.
        auto shownTip = [](QWidget* w) {
            while (w && w->toolTip().isEmpty()) w = w->parentWidget();
            return w ? w->toolTip() : QString();
        };
        std::vector<std::string> tipped;
        int rows = 0;
        for (const ParameterSpec& spec : parameterTable()) {
            if (spec.path.rfind("lpv.", 0) != 0) continue;
            const QString name = QString::fromStdString(uiObjectName(spec));
            QWidget* editor = dock->findChild<QWidget*>(name);
            QVERIFY2(editor, qPrintable(name));
            QCOMPARE(rowOf(editor)->isVisibleTo(dock), spec.isRead(doc->project().scene, 0));
            if (!spec.consoleVariable.empty()) {
                QVERIFY2(shownTip(editor).contains(QString::fromStdString(spec.consoleVariable)), qPrintable(name));
                tipped.push_back(spec.consoleVariable);
            }
            // Each editor moves its setting to another allowed value; undo brings it back.
            const nlohmann::json before = doc->value(spec.path);
            if (spec.path == "lpv.enabled") {
                enabled->setChecked(false);
            } else if (auto* d = qobject_cast<QDoubleSpinBox*>(editor)) {
                d->setValue(d->value() == d->maximum() ? d->minimum() : d->maximum());
            } else if (auto* i = qobject_cast<QSpinBox*>(editor)) {
                i->setValue(i->value() == i->maximum() ? i->minimum() : i->maximum());
            } else if (auto* c = qobject_cast<QCheckBox*>(editor)) {
                c->setChecked(!c->isChecked());
            } else {
                QFAIL(qPrintable("no editor type for " + name));
            }
            QVERIFY2(doc->value(spec.path) != before, qPrintable(name));
            undo->trigger();
            QVERIFY2(doc->value(spec.path) == before, qPrintable(name));
            ++rows;
        }
        QCOMPARE(rows, 14);
        // The tooltips name every console variable lpv.ini writes.
        LpvSettings named = doc->project().scene.lpv;
        named.size = 1.0;  // the size the terrain resolves: only the names are read here
        for (const auto& [cvar, value] : lpvConsoleVariables(named))
            QVERIFY2(std::find(tipped.begin(), tipped.end(), cvar) != tipped.end(), cvar.c_str());
        QVERIFY(shownTip(dock->findChild<QWidget*>("param.lpv.size")).startsWith("Console variable rEx.LPV.Size\n"));
        // Quality 2 shows the cone-trace samples.
        QVERIFY(!rowOf(dock->findChild<QWidget*>("param.lpv.cone_trace_samples"))->isVisibleTo(dock));
        dock->findChild<QSpinBox*>("param.lpv.quality")->setValue(2);
        QVERIFY(rowOf(dock->findChild<QWidget*>("param.lpv.cone_trace_samples"))->isVisibleTo(dock));

        // Lights: add a point and a spot light, edit, refuse a bad cone, delete, undo.
        auto* table = dock->findChild<QTableWidget*>("lights.table");
        QVERIFY(table);
        const auto& lights = doc->project().scene.lights;
        QCOMPARE(int(lights.size()), 0);
        QCOMPARE(table->rowCount(), 0);
        QVERIFY(!dock->findChild<QPushButton*>("lights.delete")->isEnabled());
        dock->findChild<QPushButton*>("lights.add")->click();
        QCOMPARE(int(lights.size()), 1);
        QCOMPARE(lights[0].type, LocalLightType::Point);
        dock->findChild<QPushButton*>("lights.addSpot")->click();
        QCOMPARE(int(lights.size()), 2);
        QCOMPARE(lights[1].type, LocalLightType::Spot);
        QCOMPARE(table->rowCount(), 2);
        QCOMPARE(table->currentRow(), 1);
        QCOMPARE(table->item(1, 0)->text(), QString("spot"));
        // The selected light's fields: spot rows shown for the spot light.
        QVERIFY(rowOf(dock->findChild<QWidget*>("param.light.outer_cone_deg"))->isVisibleTo(dock));
        dock->findChild<QDoubleSpinBox*>("param.light.intensity")->setValue(250.0);
        QCOMPARE(lights[1].intensity, 250.0);
        QCOMPARE(table->item(1, 3)->text(), QString("250"));
        dock->findChild<QDoubleSpinBox*>("param.light.range")->setValue(40.0);
        QCOMPARE(lights[1].range, 40.0);
        for (int k = 0; k < 3; ++k)
            dock->findChild<QDoubleSpinBox*>("param.light.position." + QString::number(k))->setValue(10.0 * (k + 1));
        QVERIFY(lights[1].position == glm::vec3(10.0f, 20.0f, 30.0f));
        dock->findChild<QDoubleSpinBox*>("param.light.direction.0")->setValue(0.5);
        QCOMPARE(lights[1].direction.x, 0.5f);
        dock->findChild<QDoubleSpinBox*>("param.light.inner_cone_deg")->setValue(10.0);
        dock->findChild<QDoubleSpinBox*>("param.light.outer_cone_deg")->setValue(45.0);
        QCOMPARE(lights[1].innerConeDeg, 10.0);
        QCOMPARE(lights[1].outerConeDeg, 45.0);
        QTimer::singleShot(200, [] {
            auto* dialog = qobject_cast<QColorDialog*>(QApplication::activeModalWidget());
            if (!dialog) return;
            dialog->setCurrentColor(QColor::fromRgbF(1.0f, 0.5f, 0.0f));
            dialog->accept();
        });
        dock->findChild<QPushButton*>("param.light.color")->click();
        QCOMPARE(lights[1].color.x, 1.0f);
        QCOMPARE(lights[1].color.z, 0.0f);
        // An outer cone inside the inner one is refused with the loader's own rule.
        nlohmann::json bad = doc->json();
        bad["lights"][1]["outer_cone_deg"] = 5.0;
        QString loaderSays;
        try {
            sceneFromJson(bad, "project", nullptr);
        } catch (const std::exception& e) {
            loaderSays = QString::fromStdString(e.what());
        }
        QVERIFY(loaderSays.contains("must be above inner_cone_deg (10)"));
        dock->findChild<QDoubleSpinBox*>("param.light.outer_cone_deg")->setValue(5.0);
        QCOMPARE(lights[1].outerConeDeg, 45.0);
        QCOMPARE(dock->findChild<QDoubleSpinBox*>("param.light.outer_cone_deg")->value(), 45.0);
        auto* error = dock->findChild<QLabel*>("lpv.error");
        QVERIFY(error->isVisibleTo(dock));
        QCOMPARE(error->text(), loaderSays);
        // A spot turned point hides its cone rows.
        dock->findChild<QComboBox*>("param.light.type")->setCurrentText("point");
        QCOMPARE(lights[1].type, LocalLightType::Point);
        QVERIFY(!error->isVisibleTo(dock));
        QVERIFY(!rowOf(dock->findChild<QWidget*>("param.light.outer_cone_deg"))->isVisibleTo(dock));
        undo->trigger();
        QCOMPARE(lights[1].type, LocalLightType::Spot);
        // Selecting the first light edits it.
        table->selectRow(0);
        dock->findChild<QDoubleSpinBox*>("param.light.intensity")->setValue(75.0);
        QCOMPARE(lights[0].intensity, 75.0);
        QCOMPARE(lights[1].intensity, 250.0);
        // Delete takes the selected light; undo puts it back.
        dock->findChild<QPushButton*>("lights.delete")->click();
        QCOMPARE(int(lights.size()), 1);
        QCOMPARE(lights[0].intensity, 250.0);
        QCOMPARE(table->rowCount(), 1);
        undo->trigger();
        QCOMPARE(int(lights.size()), 2);
        QCOMPARE(lights[0].intensity, 75.0);
        QCOMPARE(table->rowCount(), 2);

        while (stack->index() > startIndex) stack->undo();
        QCOMPARE(int(lights.size()), 0);
        QCOMPARE(table->rowCount(), 0);
        QVERIFY(!doc->project().scene.lpv.enabled);
        QCOMPARE(doc->project().scene.lighting.indirect, IndirectLighting::Probes);
    }

    // lighting.indirect lpv in the window: the volumes are computed on a worker, a still camera
    // computes nothing more, and a moving one at most every lpv.update_interval + 1 frames, the
    // last position's volumes landing once it stops.
    void viewportUpdatesTheLpvOnAWorkerAtItsInterval() {
        ViewportWindow* v = w_->viewport();
        ProjectDocument* doc = w_->document();
        QString error;
        QVERIFY(doc->setParameter("lpv.update_interval", 3, &error));
        QVERIFY(doc->setParameter("lighting.indirect", "lpv", &error));
        QSignalSpy landed(v, &ViewportWindow::lpvUpdated);
        QVERIFY(!v->renderer()->renderer().hasLpvResources());
        QVERIFY(doc->setParameter("lpv.enabled", true, &error));
        v->renderNow();
        QTRY_VERIFY_WITH_TIMEOUT(!landed.isEmpty(), 20000);
        QVERIFY(v->renderer()->renderer().hasLpvResources());
        QVERIFY(v->lpvCurrent());
        const uint64_t updates = v->lpvSchedule().updates(), frames = v->lpvSchedule().frames();
        for (int i = 0; i < 6; ++i) v->renderNow();
        QCOMPARE(v->lpvSchedule().updates(), updates);
        QCOMPARE(v->lpvSchedule().frames(), frames + 6);
        // Each pan moves the finest cascade by several of its cells.
        for (int i = 0; i < 12; ++i) {
            QTest::keyClick(v, Qt::Key_D);
            v->renderNow();
        }
        const uint64_t f = v->lpvSchedule().frames() - frames - 6, u = v->lpvSchedule().updates() - updates;
        QVERIFY2(u >= 1 && u <= (f + 3) / 4, qPrintable(QString("%1 updates in %2 frames").arg(u).arg(f)));
        QTRY_VERIFY_WITH_TIMEOUT(!v->lpvUpdating() && v->lpvCurrent(), 20000);
        // Off: the next frame frees the volumes.
        QVERIFY(doc->setParameter("lpv.enabled", false, &error));
        v->renderNow();
        QVERIFY(!v->renderer()->renderer().hasLpvResources());
    }

    // The LPV follows the camera: each update's volumes are made on a worker and land on the UI
    // thread, which hands the old ones to the frames still in flight rather than waiting for the
    // device (that wait held it 0.3-0.9 s an update while the view panned on lavapipe).
    void lpvUpdatesNeverHoldTheUiThread() {
        ViewportWindow* v = w_->viewport();
        ProjectDocument* doc = w_->document();
        QString error;
        const nlohmann::json interval = doc->value("lpv.update_interval"), indirect = doc->value("lighting.indirect");
        QVERIFY(doc->setParameter("lpv.update_interval", 3, &error));
        QVERIFY(doc->setParameter("lighting.indirect", "lpv", &error));
        QSignalSpy landed(v, &ViewportWindow::lpvUpdated);
        QVERIFY(settlesQuiet(v));
        Watchdog watchdog;
        QVERIFY(doc->setParameter("lpv.enabled", true, &error));
        QTRY_VERIFY_WITH_TIMEOUT(!landed.isEmpty(), 20000);
        for (int i = 0; i < 12; ++i) {
            QTest::keyClick(v, Qt::Key_D);
            QTest::qWait(60);
        }
        QTRY_VERIFY_WITH_TIMEOUT(!v->lpvUpdating() && v->lpvCurrent(), 20000);
        const qint64 worst = watchdog.worst();
        qInfo() << "LPV on and panned:" << landed.count() << "updates landed, longest UI stall" << worst << "ms";
        QVERIFY2(landed.count() >= 2, "the pans landed no update of the LPV");
        QVERIFY2(worst <= 50, qPrintable(QString("the UI thread stalled %1 ms").arg(worst)));
        QVERIFY(doc->setParameter("lpv.enabled", false, &error));
        QVERIFY(doc->setParameter("lighting.indirect", indirect, &error));
        QVERIFY(doc->setParameter("lpv.update_interval", interval, &error));
    }

    void aThousandEditsThroughTheDocks() {
        auto rss = [] {
            std::ifstream in("/proc/self/status");
            std::string line;
            while (std::getline(in, line))
                if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) * 1024.0;
            return 0.0;
        };
        const nlohmann::json start = sceneToJson(w_->document()->project().scene);
        QUndoStack* stack = w_->document()->undoStack();
        const int startIndex = stack->index();
        struct Editor {
            const char* name;
            std::vector<double> values;
        };
        const std::vector<Editor> editors = {
            {"param.sun.elevation_deg", {12.0, 35.0, 61.0}},
            {"param.sun.azimuth_deg", {90.0, 135.0, 250.0}},
            {"param.fog.density", {1.0e-5, 4.0e-5}},
            {"param.camera.exposure_ev", {-0.5, 0.0, 0.7}},
            {"param.terrain.roughness", {0.4, 0.6, 0.9}},
            {"param.ao.strength", {0.3, 1.0}},
            {"param.shadows.depth_bias", {1.0, 2.5}},
            {"param.detail.normal_strength", {0.2, 0.8}},
            {"param.water.roughness", {0.05, 0.3}},
        };
        std::vector<QDoubleSpinBox*> boxes;
        for (const Editor& e : editors) {
            auto* box = w_->findChild<QDoubleSpinBox*>(e.name);
            QVERIFY2(box, e.name);
            boxes.push_back(box);
        }
        double after100 = 0.0;
        for (int i = 0; i < 1000; ++i) {
            const size_t k = size_t(i) % editors.size();
            const auto& values = editors[k].values;
            boxes[k]->setValue(values[size_t(i / int(editors.size())) % values.size()]);
            // Every hundred edits the window catches up with what is queued (timers, a frame),
            // still without waiting on it; a frame per edit would be the GPU's pace, not the UI's.
            if (i % 100 == 99) QCoreApplication::processEvents();
            if (i == 99) after100 = rss();
        }
        // Settle: the last preview lands; then the same frame as the command line's, probes off on
        // both sides (the command line would bake at full quality, the window holds a draft).
        QVERIFY(waitForProbes(*w_, "draft preview", 60000));
        QTest::qWait(200);
        const double after1000 = rss();
        QVERIFY2(after1000 <= 1.1 * after100,
                 qPrintable(QString("resident memory %1 MB after 1000 edits, %2 MB after 100")
                                .arg(after1000 / 1e6, 0, 'f', 1).arg(after100 / 1e6, 0, 'f', 1)));
        w_->findChild<QCheckBox*>("viewport.probes")->setChecked(false);
        w_->viewport()->renderNow();
        const RenderedImage shown = w_->viewport()->grabImage();
        {
            vk::VulkanContext ctx;
            ProjectRenderer reference(ctx, w_->document()->project());
            RenderRequest q;
            q.width = shown.width;
            q.height = shown.height;
            q.probes = false;
            const RenderedImage cli = reference.render(q, w_->viewport()->camera());
            const auto d = test::compareImages(shown.rgba, cli.rgba, shown.width, shown.height);
            QVERIFY2(d.maxAbs <= 1.0 / 255.0, qPrintable(QString("max diff %1").arg(d.maxAbs)));
        }
        w_->findChild<QCheckBox*>("viewport.probes")->setChecked(true);
        QVERIFY(stack->index() > startIndex);
        while (stack->index() > startIndex) stack->undo();
        QCOMPARE(sceneToJson(w_->document()->project().scene), start);
    }

    void tradeoffStudyAppliesAPointAsOneUndoableEdit() {
        auto* panel = w_->findChild<TradeoffPanel*>();
        QVERIFY(panel);
        QVERIFY(w_->findChild<QDockWidget*>("dock.tradeoff"));
        auto* budget = w_->findChild<QSpinBox*>("tradeoff.budget");
        auto* run = w_->findChild<QPushButton*>("tradeoff.run");
        auto* table = w_->findChild<QTableWidget*>("tradeoff.table");
        auto* apply = w_->findChild<QPushButton*>("tradeoff.apply");
        auto* status = w_->findChild<QLabel*>("tradeoff.status");
        QVERIFY(budget && run && table && apply && status && w_->findChild<QWidget*>("tradeoff.chart"));
        QCOMPARE(budget->value(), 60);
        QCOMPARE(budget->minimum(), 5);
        QCOMPARE(budget->maximum(), 3600);
        budget->setValue(5);
        run->click();
        QVERIFY(panel->running());
        QVERIFY(!run->isEnabled());
        QTRY_VERIFY_WITH_TIMEOUT(!panel->running(), 120000);
        QVERIFY2(panel->result().has_value(), qPrintable(status->text()));
        const StudyResult& r = *panel->result();
        QVERIFY(!r.points.empty());
        QCOMPARE(table->rowCount(), int(r.points.size()));
        QVERIFY(!panel->chart().series.empty());
        QVERIFY(status->text().contains(QString("%1 settings in").arg(r.points.size())));
        QVERIFY(run->isEnabled());

        // The project's own settings are the study's current point.
        int current = -1, target = -1;
        for (size_t i = 0; i < r.points.size(); ++i) {
            const StudyPoint& p = r.points[i];
            // The error-map knob marks the project's map resolution too: the settings are the first.
            if (p.current && current < 0) current = int(i);
            // The rays or probe spacing knobs: a number or a grid the project can be read back for.
            if (!p.current && target < 0 && (p.knob == "rays" || p.knob == "spacing"))
                for (const std::string& set : p.sets)
                    if (set.rfind("bake.rays=", 0) == 0 || set.rfind("probe_volumes[0].grid_dims=", 0) == 0) target = int(i);
        }
        QVERIFY(current >= 0);
        QVERIFY2(target >= 0, "no rays or spacing point in a 5 s study");
        QCOMPARE(panel->projectPoint(), current);
        const StudyPoint& point = r.points[size_t(target)];

        // A click on the plot near the point selects it, in the table too.
        bool clicked = false;
        for (const auto& [series, indices] : panel->chart().series)
            for (size_t i = 0; i < indices.size() && !clicked; ++i)
                if (int(indices[i]) == target) {
                    emit series->clicked(series->at(int(i)) * 1.01);
                    clicked = true;
                }
        QVERIFY(clicked);
        QCOMPARE(panel->selectedPoint(), target);
        QCOMPARE(table->selectionModel()->selectedRows().size(), 1);
        QCOMPARE(table->selectionModel()->selectedRows().front().row(), target);
        QVERIFY(apply->isEnabled());

        // The values each assignment gives, and the ones they replace.
        ProjectDocument* doc = w_->document();
        std::vector<std::pair<std::string, nlohmann::json>> before, after;
        for (const std::string& set : point.sets) {
            const std::string path = set.substr(0, set.find('='));
            after.emplace_back(path, ProjectDocument::assignmentValue(doc->json(), set).second);
            before.emplace_back(path, doc->value(path));
        }
        QVERIFY(before != after);
        bool typedChecks = false;
        const int undoDepth = doc->undoStack()->index();
        const auto raysBefore = doc->project().scene.bake.rays;
        const auto dimsBefore = doc->project().scene.probeVolumes[0].gridDims;
        apply->click();
        QCOMPARE(doc->undoStack()->index(), undoDepth + 1);  // one edit
        for (const auto& [path, value] : after) QCOMPARE(doc->value(path).dump(), value.dump());
        // The typed project has them, read back independently of the JSON.
        for (const std::string& set : point.sets) {
            const std::string text = set.substr(set.find('=') + 1);
            if (set.rfind("bake.rays=", 0) == 0) {
                QVERIFY(doc->project().scene.bake.rays.has_value());
                QCOMPARE(*doc->project().scene.bake.rays, std::stoi(text));
                typedChecks = true;
            } else if (set.rfind("probe_volumes[0].grid_dims=", 0) == 0) {
                const auto& dims = doc->project().scene.probeVolumes[0].gridDims;
                const QStringList parts = QString::fromStdString(text).split(',');
                QCOMPARE(parts.first().toInt(), dims[0]);
                QCOMPARE(parts.last().toInt(), dims[2]);  // nx,nz or nx,ny,nz
                typedChecks = true;
            }
        }
        QVERIFY(typedChecks);
        QCOMPARE(panel->projectPoint(), target);
        QVERIFY(!apply->isEnabled());  // it is the project's now
        QVERIFY2(status->text().contains("measured before the edit") &&
                     status->text().contains(QString::fromStdString(point.label)),
                 qPrintable(status->text()));
        QVERIFY(table->item(target, table->columnCount() - 1)->text().contains("now"));

        // Undo restores every value in one step.
        doc->undoStack()->undo();
        QCOMPARE(doc->undoStack()->index(), undoDepth);
        for (const auto& [path, value] : before) QCOMPARE(doc->value(path).dump(), value.dump());
        QCOMPARE(doc->project().scene.bake.rays, raysBefore);
        QCOMPARE(doc->project().scene.probeVolumes[0].gridDims, dimsBefore);
        QCOMPARE(panel->projectPoint(), current);
        QVERIFY(!status->text().contains("measured before the edit"));

        // Double-clicking the row applies it too.
        emit table->cellDoubleClicked(target, 0);
        QCOMPARE(doc->undoStack()->index(), undoDepth + 1);
        for (const auto& [path, value] : after) QCOMPARE(doc->value(path).dump(), value.dump());
        doc->undoStack()->undo();
    }

    void tradeoffStudyCancelsAndKeepsTheLastResult() {
        auto* panel = w_->findChild<TradeoffPanel*>();
        QVERIFY(panel);
        auto* budget = w_->findChild<QSpinBox*>("tradeoff.budget");
        auto* run = w_->findChild<QPushButton*>("tradeoff.run");
        auto* cancel = w_->findChild<QPushButton*>("tradeoff.cancel");
        auto* progress = w_->findChild<QProgressBar*>("tradeoff.progress");
        auto* status = w_->findChild<QLabel*>("tradeoff.status");
        QVERIFY(!cancel->isEnabled());
        budget->setValue(3600);
        run->click();
        QVERIFY(panel->running());
        QVERIFY(cancel->isEnabled());
        QTest::qWait(1500);
        QVERIFY(panel->running());
        QElapsedTimer timer;
        timer.start();
        cancel->click();
        QTRY_VERIFY_WITH_TIMEOUT(!panel->running(), 10000);
        QVERIFY2(timer.elapsed() < 5000, qPrintable(QString("cancel took %1 ms").arg(timer.elapsed())));
        QVERIFY(run->isEnabled());
        QVERIFY(!cancel->isEnabled());
        QCOMPARE(progress->value(), 0);
        QVERIFY(!panel->result().has_value());
        QVERIFY2(status->text().contains("Cancelled"), qPrintable(status->text()));
        // A finished study stays shown through a cancelled one.
        budget->setValue(5);
        run->click();
        QTRY_VERIFY_WITH_TIMEOUT(!panel->running(), 120000);
        QVERIFY(panel->result().has_value());
        const size_t points = panel->result()->points.size();
        budget->setValue(3600);
        run->click();
        QTest::qWait(500);
        cancel->click();
        QTRY_VERIFY_WITH_TIMEOUT(!panel->running(), 10000);
        QVERIFY(panel->result().has_value());
        QCOMPARE(panel->result()->points.size(), points);
        QCOMPARE(w_->findChild<QTableWidget*>("tradeoff.table")->rowCount(), int(points));
        QVERIFY2(status->text().contains("last study is still shown"), qPrintable(status->text()));
    }

    void screenshot() {
        w_->viewport()->renderNow();
        // The frame at full resolution, not one drawn small while the view changes.
        QVERIFY(settlesQuiet(w_->viewport()));
        QCOMPARE(w_->viewport()->presentedScale(), 1.0);
        const QPixmap shot = w_->screen()->grabWindow(0, w_->x(), w_->y(), w_->frameGeometry().width(), w_->frameGeometry().height());
        QVERIFY(shot.save(QString::fromStdString((kOut / "main_window.png").string())));
        // The Bake & Export dock after a (quick) bake: output folder and report table.
        quickBakeSettings(*w_->document());
        w_->findChild<QDockWidget*>("dock.bakeExport")->raise();
        w_->startBake();
        QVERIFY(QTest::qWaitFor([&] { return !w_->bakes()->running() && w_->probeSource() == "last bake"; }, 60000));
        QTest::qWait(200);
        QVERIFY(w_->findChild<QTableWidget*>("bake.report")->parentWidget()->grab().save(QString::fromStdString((kOut / "bake_dock.png").string())));
        // The Shadows dock in manual mode, its split chart with draggable handles.
        w_->findChild<QComboBox*>("param.shadows.split_mode")->setCurrentText("manual");
        w_->findChild<QDockWidget*>("dock.shadows")->raise();
        w_->viewport()->renderNow();
        QTest::qWait(300);
        const QPixmap dock = w_->screen()->grabWindow(0, w_->x(), w_->y(), w_->frameGeometry().width(), w_->frameGeometry().height());
        QVERIFY(dock.save(QString::fromStdString((kOut / "shadows_dock.png").string())));
        // The Surface dock with the height ramp, the horizon AO landed in the viewport.
        w_->findChild<QComboBox*>("param.terrain.albedo_mode")->setCurrentText("ramp");
        w_->findChild<QCheckBox*>("param.ao.enabled")->setChecked(true);
        QTRY_VERIFY_WITH_TIMEOUT(w_->findChild<QLabel*>("ao.status")->text().contains("directions over"), 20000);
        w_->findChild<QDockWidget*>("dock.surface")->raise();
        w_->viewport()->renderNow();
        QTest::qWait(300);
        const QPixmap surface = w_->screen()->grabWindow(0, w_->x(), w_->y(), w_->frameGeometry().width(), w_->frameGeometry().height());
        QVERIFY(surface.save(QString::fromStdString((kOut / "surface_dock.png").string())));
        // The Water dock with a lake and the choppy preset.
        w_->findChild<QDockWidget*>("dock.water")->raise();
        w_->findChild<QCheckBox*>("param.water.enabled")->setChecked(true);
        auto* preset = w_->findChild<QComboBox*>("water.preset");
        emit preset->activated(preset->findText("choppy lake"));
        w_->viewport()->renderNow();
        QTest::qWait(300);
        const QPixmap waterShot = w_->screen()->grabWindow(0, w_->x(), w_->y(), w_->frameGeometry().width(), w_->frameGeometry().height());
        QVERIFY(waterShot.save(QString::fromStdString((kOut / "water_dock.png").string())));
        // The Reflection Probes dock with the preview's probes, their markers and one inspected.
        w_->findChild<QCheckBox*>("param.water.enabled")->setChecked(false);
        w_->findChild<QDockWidget*>("dock.reflectionProbes")->raise();
        w_->findChild<QCheckBox*>("param.reflection_probes.enabled")->setChecked(true);
        w_->findChild<QCheckBox*>("viewport.probePositions")->setChecked(true);
        QTRY_VERIFY_WITH_TIMEOUT(w_->findChild<QLabel*>("reflection.status")->text().startsWith("16 probes"), 60000);
        w_->findChild<QSpinBox*>("reflection.probe")->setValue(5);
        w_->viewport()->renderNow();
        QTest::qWait(300);
        const QPixmap reflectionShot = w_->screen()->grabWindow(0, w_->x(), w_->y(), w_->frameGeometry().width(), w_->frameGeometry().height());
        QVERIFY(reflectionShot.save(QString::fromStdString((kOut / "reflection_dock.png").string())));
        // The LPV dock with the volumes on and a spot light selected.
        w_->findChild<QDockWidget*>("dock.lpv")->raise();
        w_->findChild<QCheckBox*>("param.lpv.enabled")->setChecked(true);
        w_->findChild<QComboBox*>("param.lighting.indirect")->setCurrentText("both");
        w_->findChild<QPushButton*>("lights.add")->click();
        w_->findChild<QPushButton*>("lights.addSpot")->click();
        // The dock is taller than the window: scroll to the lights; the panel's own grab has it all.
        QTest::qWait(100);  // the light's rows laid out
        auto* lightsTable = w_->findChild<QTableWidget*>("lights.table");
        QScrollArea* area = nullptr;
        for (QWidget* p = lightsTable; p && !area; p = p->parentWidget()) area = qobject_cast<QScrollArea*>(p);
        QVERIFY(area);
        area->verticalScrollBar()->setValue(lightsTable->mapTo(area->widget(), QPoint(0, 0)).y() - 8);
        QVERIFY(area->verticalScrollBar()->value() > 0);
        w_->viewport()->renderNow();
        QTest::qWait(300);
        QVERIFY(w_->findChild<LpvPanel*>()->grab().save(QString::fromStdString((kOut / "lpv_panel.png").string())));
        const QPixmap lpvShot = w_->screen()->grabWindow(0, w_->x(), w_->y(), w_->frameGeometry().width(), w_->frameGeometry().height());
        QVERIFY(lpvShot.save(QString::fromStdString((kOut / "lpv_dock.png").string())));
        // The Trade-off dock after a short study, a rays point selected.
        w_->findChild<QDockWidget*>("dock.tradeoff")->raise();
        auto* tradeoff = w_->findChild<TradeoffPanel*>();
        w_->findChild<QSpinBox*>("tradeoff.budget")->setValue(5);
        w_->findChild<QPushButton*>("tradeoff.run")->click();
        QTRY_VERIFY_WITH_TIMEOUT(!tradeoff->running(), 120000);
        QVERIFY(tradeoff->result().has_value());
        for (size_t i = 0; i < tradeoff->result()->points.size(); ++i)
            if (tradeoff->result()->points[i].knob == "rays") tradeoff->selectPoint(int(i));
        QTest::qWait(300);
        QVERIFY(tradeoff->grab().save(QString::fromStdString((kOut / "tradeoff_panel.png").string())));
        const QPixmap tradeoffShot = w_->screen()->grabWindow(0, w_->x(), w_->y(), w_->frameGeometry().width(), w_->frameGeometry().height());
        QVERIFY(tradeoffShot.save(QString::fromStdString((kOut / "tradeoff_dock.png").string())));
    }
};

QTEST_MAIN(UiTest)
#include "test_ui.moc"
