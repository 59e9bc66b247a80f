#include "MainWindow.h"

#include <array>
#include <chrono>
#include <functional>

#include <QAbstractSpinBox>
#include <cmath>

#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QCloseEvent>
#include <QComboBox>
#include <QDateTime>
#include <QDir>
#include <QDockWidget>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QKeyEvent>
#include <QLabel>
#include <QLineEdit>
#include <QLocale>
#include <QMenuBar>
#include <QMessageBox>
#include <QProgressBar>
#include <QToolButton>
#include <QProxyStyle>
#include <QPushButton>
#include <QScrollArea>
#include <QScrollBar>
#include <QSettings>
#include <QSignalBlocker>
#include <QStandardPaths>
#include <QStatusBar>
#include <QStyleOptionTab>
#include <QTabBar>
#include <QTableWidget>
#include <QSlider>
#include <QToolBar>
#include <QVBoxLayout>

#include "CascadeSplitChart.h"
#include "ProbeInspector.h"
#include "ViewportGizmos.h"
#include "bake/HeightfieldTracer.h"

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>
#include "SceneLighting.h"
#include "DemImport.h"
#include "ParameterPanels.h"
#include "WaterPanel.h"
#include "KeptPlacement.h"
#include "ParameterTable.h"
#include "BakeJob.h"
#include "PreviewBake.h"
#include "LpvPanel.h"
#include "ScenarioPanel.h"
#include "ReflectionPanel.h"
#include "TradeoffPanel.h"
#include "ShProbeFile.h"
#include "bake/DiffuseBake.h"
#include "bake/ProbeDiagnostics.h"
#include "bake/ProbePlacement.h"
#include "render/TerrainRenderer.h"
#include "scene/DebugViews.h"
#include "system/BackgroundPriority.h"

namespace terralux {

namespace {

std::vector<std::string> surfaceExtensions(QVulkanInstance& inst) {
    std::vector<std::string> out;
    for (const auto& e : inst.supportedExtensions()) {
        const QByteArray name = e.name;
        if (name == "VK_KHR_surface" || name.endsWith("_surface")) out.push_back(name.toStdString());
    }
    return out;
}

// Keeps a vertically scrolled dock at least as wide as its rows, which grow when a list shows
// more items (a ramp's stops) than it had when the dock was built.
class FitWidth : public QObject {
public:
    explicit FitWidth(QScrollArea* area) : QObject(area), area_(area) { fit(); }
    bool eventFilter(QObject* watched, QEvent* e) override {
        if (e->type() == QEvent::LayoutRequest) fit();
        return QObject::eventFilter(watched, e);
    }

private:
    void fit() {
        area_->setMinimumWidth(area_->widget()->minimumSizeHint().width() + area_->verticalScrollBar()->sizeHint().width());
    }
    QScrollArea* area_;
};

QWidget* scrolled(QWidget* w) {
    auto* area = new QScrollArea;
    area->setWidget(w);
    area->setWidgetResizable(true);
    area->setFrameShape(QFrame::NoFrame);
    // Scroll only vertically: the dock is at least as wide as its rows plus the scroll bar.
    area->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
    w->installEventFilter(new FitWidth(area));
    return area;
}

// QMainWindow shows a tabbed dock's title as its tab label, where '&' marks a mnemonic; dock
// titles are plain text ("Sun & Sky", as in the title bar), so the dock tabs draw them literally.
class DockTabStyle : public QProxyStyle {
public:
    void drawControl(ControlElement element, const QStyleOption* option, QPainter* painter,
                     const QWidget* widget) const override {
        if (element == CE_TabBarTabLabel)
            if (const auto* tab = qstyleoption_cast<const QStyleOptionTab*>(option)) {
                QStyleOptionTab literal(*tab);
                literal.text.replace('&', "&&");
                return QProxyStyle::drawControl(element, &literal, painter, widget);
            }
        QProxyStyle::drawControl(element, option, painter, widget);
    }
    QSize sizeFromContents(ContentsType type, const QStyleOption* option, const QSize& size,
                           const QWidget* widget) const override {
        QSize out = QProxyStyle::sizeFromContents(type, option, size, widget);
        if (type == CT_TabBarTab)
            if (const auto* tab = qstyleoption_cast<const QStyleOptionTab*>(option))
                // The tab bar measured the label without its '&'s.
                out.rwidth() += int(tab->text.count('&')) * tab->fontMetrics.horizontalAdvance('&');
        return out;
    }
};

// Whether Undo/Redo typed into `w` should reach the document's undo stack rather than the widget.
// Spin boxes commit every value they show, so their own text undo only confuses; a line edit
// keeps its text undo while it holds typing of its own (setText after a commit clears it).
bool documentUndoWins(QWidget* w, bool undo) {
    for (QWidget* p = w; p; p = p->parentWidget())
        if (qobject_cast<QAbstractSpinBox*>(p)) return true;
    if (auto* edit = qobject_cast<QLineEdit*>(w)) return !(undo ? edit->isUndoAvailable() : edit->isRedoAvailable());
    return true;
}

QString percent(const nlohmann::json& v) {
    return v.is_number() ? QString("%1 %").arg(v.get<double>() * 100.0, 0, 'f', 2) : QString("—");
}

QString formatBytes(double bytes) {
    if (bytes < 1024) return QString::number(bytes) + " B";
    if (bytes < 1024 * 1024) return QString::number(bytes / 1024.0, 'f', 1) + " KiB";
    return QString::number(bytes / (1024.0 * 1024.0), 'f', 1) + " MiB";
}

// The terrain's level of detail as the status bar shows it: its triangles and the most its
// surface strays from the DEM on screen (TerrainRenderer::LodChoice).
QString terrainLodText(const TerrainRenderer::LodChoice& lod) {
    const double t = double(lod.triangles);
    const QString tris = t >= 1e6 ? QString("%1 M").arg(t / 1e6, 0, 'f', 1)
                         : t >= 1e3 ? QString("%1 k").arg(t / 1e3, 0, 'f', 0)
                                    : QString::number(lod.triangles);
    return QString("terrain %1 tris, %2 px").arg(tris).arg(lod.screenErrorPixels, 0, 'f', 2);
}

// A status line of a dock: plain text that wraps, found by `name` in tests.
QLabel* statusLabel(const char* name) {
    auto* label = new QLabel;
    label->setObjectName(name);
    label->setWordWrap(true);
    return label;
}

}  // namespace

MainWindow::MainWindow(QWidget* parent) : QMainWindow(parent), doc_(new ProjectDocument(this)) {
    setObjectName("mainWindow");
    tabStyle_ = new DockTabStyle;
    tabStyle_->setParent(this);
    // Our device, on an instance Qt can make surfaces for.
    {
        QVulkanInstance probe;
        probe.create();
        vk::ContextOptions options;
        options.instanceExtensions = surfaceExtensions(probe);
        options.swapchain = true;
        ctx_ = std::make_unique<vk::VulkanContext>(options);
    }
    vulkan_.setVkInstance(ctx_->instance());
    if (!vulkan_.create()) throw vk::VulkanUnavailable("Qt cannot use the Vulkan instance for windows");

    bake_ = new BakeController(this);
    viewport_ = new ViewportWindow(*ctx_, &vulkan_);
    gizmos_ = new ViewportGizmos(doc_, this);
    viewport_->setInteraction(gizmos_);
    connect(gizmos_, &ViewportGizmos::redraw, viewport_, &QWindow::requestUpdate);
    connect(gizmos_, &ViewportGizmos::rejected, this, &MainWindow::showRejection);
    connect(gizmos_, &ViewportGizmos::selectionChanged, this, [this](const QString& name) {
        if (name.isEmpty()) return;
        statusBar()->showMessage(name + " selected: drag its handles (Esc cancels a drag, Ctrl+Z undoes it)", 6000);
    });
    auto* container = QWidget::createWindowContainer(viewport_, this);
    container->setObjectName("viewport");
    container->setMinimumSize(480, 320);
    container->setFocusPolicy(Qt::StrongFocus);
    setCentralWidget(container);

    buildDocks();
    buildMenus();

    previewTimer_.setSingleShot(true);
    previewTimer_.setInterval(150);
    connect(&previewTimer_, &QTimer::timeout, this, &MainWindow::startPreview);
    autosaveTimer_.setInterval(qEnvironmentVariableIntValue("TERRALUX_AUTOSAVE_MS") > 0
                                   ? qEnvironmentVariableIntValue("TERRALUX_AUTOSAVE_MS")
                                   : 60000);
    connect(&autosaveTimer_, &QTimer::timeout, this, &MainWindow::autosave);
    autosaveTimer_.start();
    // Undo and redo reach the document from every dock, floating ones too (eventFilter).
    qApp->installEventFilter(this);

    connect(doc_, &ProjectDocument::terrainChanged, this, &MainWindow::rebuildRenderer);
    connect(doc_, &ProjectDocument::parametersChanged, this, [this](const QString& path) {
        // The parameter table says what an edit invalidates; do that much and no more.
        const unsigned work = invalidatedBy(path.toStdString());
        if (work & (kUpload | kRebake | kReplace | kReimport)) refreshLighting();
        else viewport_->requestUpdate();
        if ((work & (kReplace | kReimport)) || path.startsWith("bake.")) updateEstimate();
        if (work & (kRebake | kReplace | kReimport)) schedulePreview();
    });
    connect(doc_, &ProjectDocument::terrainEditFailed, this,
            [this](const QString& m) { showError("Terrain", m); });
    connect(doc_, &ProjectDocument::terrainLoadingChanged, this, [this](bool loading) {
        terrainBusy_->setVisible(loading);
        if (loading) statusBar()->showMessage("importing the terrain…");
        else statusBar()->clearMessage();
    });
    connect(doc_, &ProjectDocument::fileChanged, this, &MainWindow::updateTitle);
    connect(doc_, &ProjectDocument::fileChanged, this, &MainWindow::updateOutputPath);
    connect(doc_, &ProjectDocument::parametersChanged, this, &MainWindow::updateOutputPath);
    connect(viewport_, &ViewportWindow::clicked, this, [this](QPointF at) {
        const QSizeF size(viewport_->width(), viewport_->height());
        // Right on a bound's edge or handle, the bound; near one, a probe marker comes first
        // (the outer probes of a terrain grid stand on its edges), then the bound.
        if (gizmos_->select(at, viewport_->camera(), size, 3.0, true)) {
            raiseDockOf(gizmos_->selected()->kind);
            return;
        }
        if (const int probe = reflectionProbeAt(at); probe >= 0) {
            reflectionPanel_->inspect(probe);
            findChild<QDockWidget*>("dock.reflectionProbes")->raise();
            statusBar()->showMessage(QString("reflection probe %1").arg(probe), 4000);
            return;
        }
        if (const auto probe = diffuseProbeAt(at)) {
            probeInspector_->showPoint(std::nullopt);
            probeInspector_->inspect(probe->first, probe->second);
            findChild<QDockWidget*>("dock.probeVolumes")->raise();
            statusBar()->showMessage(QString("probe %1 of '%2'")
                                         .arg(probe->second)
                                         .arg(QString::fromStdString((*renderer_->boundVolumes())[size_t(probe->first)].name)),
                                     4000);
            return;
        }
        if (gizmos_->select(at, viewport_->camera(), size)) {
            raiseDockOf(gizmos_->selected()->kind);
            return;
        }
        // The terrain under the click: which probes light it.
        if (const auto point = terrainPointAt(at)) {
            probeInspector_->showPoint(point);
            findChild<QDockWidget*>("dock.probeVolumes")->raise();
        }
    });
    connect(viewport_, &ViewportWindow::frameRendered, this, [this](double ms) {
        // The wall time of the frame on this thread; the GPU's time from the frame graph's
        // timestamps and the host's recording, of the last frame known finished.
        QString text = QString("frame %1 ms").arg(ms, 0, 'f', 1);
        // Drawn at fewer pixels while the view changes (dynamic resolution).
        if (viewport_->presentedScale() < 1.0)
            text += QString(" · %1 % res").arg(std::lround(100.0 * viewport_->presentedScale() * viewport_->presentedScale()));
        if (viewport_->renderer()) {
            const FrameTimings& t = viewport_->renderer()->renderer().lastFrameTimings();
            if (t.gpuTimed()) text += QString(" · GPU %1 ms").arg(t.gpuMilliseconds, 0, 'f', 2);
            if (t.recordMilliseconds > 0.0) text += QString(" · host %1 ms").arg(t.recordMilliseconds, 0, 'f', 1);
            text += " · " + terrainLodText(viewport_->renderer()->renderer().lastLod());
            // A metered exposure is shown as it adapts: what the camera is at now.
            const double ev = viewport_->renderer()->shownEv100();
            if (std::isfinite(ev)) text += QString(" · EV100 %1").arg(ev, 0, 'f', 2);
            probeInspector_->setShownEv100(ev);
            reflectionPanel_->setShownEv100(ev);
        }
        frameLabel_->setText(text);
        frameLabel_->setToolTip("Wall time of the last frame; % res: the share of the window's pixels it was drawn "
                                "at while the view changes (View > Dynamic resolution); GPU: its passes' time from "
                                "timestamps; host: recording it (the per-pass times: terralux --render --profile); "
                                "terrain: its triangles at the level of detail and the most its surface strays "
                                "from the DEM on screen (over 1 px only where the detail budget binds); "
                                "EV100: the camera's exposure (metered in modes average and histogram)");
    });
    connect(viewport_, &ViewportWindow::lpvUpdated, this, [this](double ms) {
        statusBar()->showMessage(QString("light propagation volumes updated in %1 ms").arg(ms, 0, 'f', 0), 3000);
        updateLegend();
    });
    // The practical cascade splits the Shadows dock shows and writes depend on the view's shape.
    auto updateAspect = [this] {
        if (viewport_->width() > 0 && viewport_->height() > 0)
            doc_->setViewAspect(double(viewport_->width()) / double(viewport_->height()));
    };
    connect(viewport_, &QWindow::widthChanged, this, updateAspect);
    connect(viewport_, &QWindow::heightChanged, this, updateAspect);
    connect(viewport_, &ViewportWindow::cameraChanged, this, [this] {
        const OrbitCamera& c = viewport_->camera();
        doc_->setCameraQuietly({{"target", {c.target.x, c.target.y, c.target.z}},
                                {"radius", c.radius},
                                {"azimuth_deg", c.azimuthDeg},
                                {"elevation_deg", c.elevationDeg},
                                {"fov_deg", c.fovDeg}});
    });
    connect(bake_, &BakeController::progress, this, [this](double f, const QString& phase, double eta) {
        progress_->setValue(int(f * 100.0));
        eta_->setText(eta >= 0 ? QString("%1 — ETA %2 s").arg(phase).arg(eta, 0, 'f', 0) : phase);
    });
    connect(bake_, &BakeController::finished, this, [this](const nlohmann::json& report) {
        progress_->setValue(100);
        eta_->setText(QString("done in %1 s").arg(report["time_s"].get<double>(), 0, 'f', 2));
        showReport(report);
        bakeButton_->setEnabled(true);
        cancelButton_->setEnabled(false);
        if (renderer_) {
            // Show what this bake wrote, wherever it went, and say where that was.
            const auto own = bakeFolder();
            renderer_->setProject(doc_->project());
            renderer_->loadProbes(false, nullptr, nullptr, bakeOutDir_);
            probeSource_ = withStaleness(own && *own == bakeOutDir_
                                             ? QString("last bake")
                                             : "export in " + QString::fromStdString(bakeOutDir_.string()));
            showBoundProbes();
            viewport_->requestUpdate();
            updateStatus();
        }
    });
    connect(bake_, &BakeController::cancelled, this, [this] {
        eta_->setText("cancelled: earlier outputs untouched");
        progress_->setValue(0);
        bakeButton_->setEnabled(true);
        cancelButton_->setEnabled(false);
        schedulePreview();  // what the bake would have shown, as a draft again
    });
    connect(bake_, &BakeController::failed, this, [this](const QString& m) {
        eta_->setText("failed");
        bakeButton_->setEnabled(true);
        cancelButton_->setEnabled(false);
        schedulePreview();
        showError("Bake", m);
    });

    drainPoll_.setInterval(10);
    connect(&drainPoll_, &QTimer::timeout, this, [this] {
        // A renderer being made on a worker is installed once made. The old renderer goes at one
        // tick, once its frames and its workers have finished (its destruction waits for
        // nothing), and the new one is started at the next.
        if (makingRenderer_.valid()) {
            if (makingRenderer_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
            if (tearingDown()) return;
            std::unique_ptr<ProjectRenderer> made;
            try {
                made = makingRenderer_.get();
            } catch (const std::exception& e) {
                if (remakeRenderer_) {  // it was for a terrain since replaced: make the new one
                    remakeRenderer_ = false;
                    buildRenderer();
                    return;
                }
                drainPoll_.stop();
                showError("Viewport", QString("cannot draw this terrain: %1").arg(e.what()));
                return;
            }
            ++renderersMadeOnWorkers_;
            if (remakeRenderer_) {
                // Made for a terrain since replaced: it drew nothing; it goes as a retired one does.
                remakeRenderer_ = false;
                retiredRenderer_ = std::move(made);
                return;
            }
            drainPoll_.stop();
            installRenderer(std::move(made));
            return;
        }
        if (retiredRenderer_) {
            if (!drain_.done() || !retiredRenderer_->renderer().workersFinished() || tearingDown()) return;
            drain_ = vk::Submission();
            tearingDown_ = std::async(std::launch::async, [this, old = std::move(retiredRenderer_)]() mutable {
                const BackgroundThread background;
                old.reset();
                ++renderersTornDownOnWorkers_;
            });
            return;
        }
        buildRenderer();
    });
    buildRenderer(true);
    updateEstimate();
    updateTitle();
    updateOutputPath();
    resize(1400, 860);
    // The viewport is what a TD looks at: the docks start at two fifths of the window, or as wide
    // as their tab labels need.
    resizeDocks({findChild<QDockWidget*>("dock.terrain")}, {std::max(width() * 2 / 5, 560)}, Qt::Horizontal);
}

MainWindow::~MainWindow() {
    previewJob_.stop();
    stopAmbientOcclusion();
    bake_->cancel();
    bake_->wait();
    delete viewport_;  // before the device it presents with
    viewport_ = nullptr;
    renderer_.reset();
    retiredRenderer_.reset();
    drain_ = vk::Submission();
    if (makingRenderer_.valid()) {
        try {
            makingRenderer_.get();  // made, it goes now, before the device
        } catch (const std::exception&) {
        }
    }
    if (tearingDown_.valid()) tearingDown_.wait();
}

bool MainWindow::tearingDown() const {
    return tearingDown_.valid() && tearingDown_.wait_for(std::chrono::seconds(0)) != std::future_status::ready;
}

QString MainWindow::autosaveDir() {
    const QString env = qEnvironmentVariable("TERRALUX_AUTOSAVE_DIR");
    return env.isEmpty() ? QStandardPaths::writableLocation(QStandardPaths::AppDataLocation) : env;
}

QDockWidget* MainWindow::addDock(const QString& title, const QString& name, QWidget* w) {
    // A dock title is plain text: '&' needs no escaping here (unlike buttons and actions).
    auto* d = new QDockWidget(title, this);
    d->setObjectName(name);
    d->setWidget(scrolled(w));
    addDockWidget(Qt::RightDockWidgetArea, d);
    return d;
}

void MainWindow::showRejection(const QString& message) { statusBar()->showMessage(message, 8000); }

ParameterForm* MainWindow::dockForm(const std::string& dockName) {
    auto* form = new ParameterForm(doc_);
    for (const auto& spec : parameterTable())
        if (spec.uiRow && parameterDock(spec).objectName == dockName) form->addParameter(spec.path);
    reportRejections(form);
    form->refresh();
    return form;
}

// The terrain: what was imported, the import button and the terrain rows.
QDockWidget* MainWindow::buildTerrainDock() {
    auto* terrain = new QWidget;
    auto* tv = new QVBoxLayout(terrain);
    terrainSummary_ = statusLabel("terrain.summary");
    tv->addWidget(terrainSummary_);
    auto* importDem = new QPushButton("Import DEM…");
    importDem->setObjectName("terrain.import");
    tv->addWidget(importDem);
    tv->addWidget(dockForm("dock.terrain"));
    tv->addStretch(1);
    connect(importDem, &QPushButton::clicked, this, [this] {
        const QString f = QFileDialog::getOpenFileName(this, "Import DEM", QString(),
                                                       "Rasters (*.tif *.tiff *.hgt *.asc *.vrt *.zip *.img *.dem);;All files (*)");
        if (!f.isEmpty()) importDemFile(f);
    });
    return addDock("Terrain", "dock.terrain", terrain);
}

// Sun & Sky.
QDockWidget* MainWindow::buildSunSkyDock() {
    auto* sky = new ParameterForm(doc_);
    sky->addParameters("sun.");
    // Where the date and time put the sun, so the slider's effect reads in degrees.
    auto* position = statusLabel("sun.position");
    sky->addWidget("", position);
    auto showPosition = [this, position] {
        const SceneDescription& scene = doc_->project().scene;
        const bool image = sunFromSkyImage(scene);
        position->setVisible(image || scene.sun.mode == SunMode::DateTime);
        if (image) {
            // The image's sun: no slider places it, so the dock says where it stands.
            try {
                const ImageSun sun = imageSunOf(lightingOf(doc_->project(), doc_->terrain().heightfield));
                position->setText(sun.illuminanceLux > 0.0
                                      ? QString("Sun from the image at azimuth %1°, %2° above the horizon, %3 lx, radius %4° "
                                                "(%5 % of the image's light)")
                                            .arg(sun.azimuthDeg, 0, 'f', 1)
                                            .arg(sun.elevationDeg, 0, 'f', 1)
                                            .arg(sun.illuminanceLux, 0, 'f', 0)
                                            .arg(sun.angularRadiusDeg, 0, 'f', 2)
                                            .arg(100.0 * sun.shareOfSky, 0, 'f', 1)
                                      : QString("The image has no sun: it lights alone"));
            } catch (const std::exception& e) {
                position->setText(QString::fromStdString(e.what()));
            }
            return;
        }
        if (scene.sun.mode != SunMode::DateTime) return;
        try {
            const SunAngles a = sunAnglesOf(scene, doc_->terrain().heightfield);
            position->setText(QString("Sun at azimuth %1° (%2° from true north), %3° above the horizon%4")
                                  .arg(a.azimuthDeg, 0, 'f', 1)
                                  .arg(a.place->position.azimuthDeg, 0, 'f', 1)
                                  .arg(a.elevationDeg, 0, 'f', 1)
                                  .arg(a.elevationDeg < 0.0 ? ": night" : ""));
        } catch (const std::exception& e) {
            position->setText(QString::fromStdString(e.what()));
        }
    };
    connect(doc_, &ProjectDocument::parametersChanged, position, showPosition);
    connect(doc_, &ProjectDocument::terrainChanged, position, showPosition);
    showPosition();
    sky->addParameters("sky.");
    auto* importHdr = new QPushButton("Import HDR…");
    importHdr->setObjectName("sky.import");
    sky->addWidget("", importHdr);
    connect(importHdr, &QPushButton::clicked, this, [this] {
        const QString f = QFileDialog::getOpenFileName(this, "Import HDR sky", QString(), "HDR images (*.hdr *.exr);;All files (*)");
        if (!f.isEmpty()) importHdrFile(f);
    });
    reportRejections(sky);
    sky->refresh();
    // The project's own sun and sky are the default scenario's: the panel shows these rows for it.
    scenarioPanel_ = new ScenarioPanel(doc_, sky);
    connect(scenarioPanel_, &ScenarioPanel::rejected, this, [this](const QString& m) { statusBar()->showMessage(m, 8000); });
    connect(scenarioPanel_, &ScenarioPanel::currentScenarioChanged, this, [this](const QString& name) {
        // What is edited is what is shown.
        if (name.toStdString() != scenarioView_.a || scenarioView_.blends())
            setScenarioView({name.toStdString(), name.toStdString(), 0.0f});
    });
    return addDock("Sun & Sky", "dock.sunSky", scenarioPanel_);
}

// Shadows: the table's rows with the cascade splits over the view below the split rows, and
// the cascade view.
QDockWidget* MainWindow::buildShadowsDock() {
    auto* shadows = new QWidget;
    auto* sv = new QVBoxLayout(shadows);
    auto* sf = new ParameterForm(doc_);
    auto* chartBox = new QWidget;
    auto* cv = new QVBoxLayout(chartBox);
    cv->setContentsMargins(0, 4, 0, 4);
    cv->addWidget(new QLabel("Cascade splits, distance from the camera:"));
    auto* chart = new CascadeSplitChart(doc_);
    cv->addWidget(chart);
    for (const auto& spec : parameterTable()) {
        if (!spec.uiRow || spec.path.rfind("shadows.", 0) != 0) continue;
        sf->addParameter(spec.path);
        if (spec.path == "shadows.splits") sf->addWidget(chartBox);
    }
    reportRejections(sf);
    reportRejections(chart);
    sf->refresh();
    sv->addWidget(sf);
    showCascades_ = new QPushButton("Show cascades");
    showCascades_->setObjectName("shadows.showCascades");
    showCascades_->setCheckable(true);
    showCascades_->setToolTip("Shows debug view 34 (each cascade in its colour of the chart); unchecked, "
                              "the view shown before");
    sv->addWidget(showCascades_);
    sv->addStretch(1);
    return addDock("Shadows", "dock.shadows", shadows);
}

// Atmosphere: height fog, and the exposure and anti-aliasing of the whole image.
QDockWidget* MainWindow::buildAtmosphereDock() {
    auto* atmosphere = new ParameterForm(doc_);
    atmosphere->addParameters("fog.");
    for (const char* path : {"camera.exposure_mode", "camera.ev100", "camera.exposure_ev", "camera.adaptation_s",
                             "camera.antialiasing"})
        atmosphere->addParameter(path);
    reportRejections(atmosphere);
    atmosphere->refresh();
    return addDock("Atmosphere", "dock.atmosphere", atmosphere);
}

// Surface: albedo, roughness and micro-detail.
QDockWidget* MainWindow::buildSurfaceDock() {
    auto* surface = new QWidget;
    auto* uv = new QVBoxLayout(surface);
    uv->addWidget(dockForm("dock.surface"));
    auto* importAlbedo = new QPushButton("Import albedo map…");
    importAlbedo->setObjectName("surface.importAlbedo");
    importAlbedo->setToolTip("An orthophoto or any RGB raster GDAL reads, draped over the DEM by its georeferencing");
    uv->addWidget(importAlbedo);
    connect(importAlbedo, &QPushButton::clicked, this, [this] {
        const QString f = QFileDialog::getOpenFileName(this, "Import albedo map", QString(),
                                                       "Rasters (*.tif *.tiff *.png *.jpg *.jpeg *.vrt *.jp2);;All files (*)");
        if (f.isEmpty()) return;
        QString error;
        if (!doc_->importAlbedoMap(f, &error)) showError("Import albedo map", error);
    });
    albedoStatus_ = statusLabel("surface.albedoStatus");
    uv->addWidget(albedoStatus_);
    uv->addStretch(1);
    return addDock("Surface", "dock.surface", surface);
}

// Ambient occlusion: its settings and the progress of the field.
QDockWidget* MainWindow::buildAoDock() {
    auto* ao = new QWidget;
    auto* av = new QVBoxLayout(ao);
    av->addWidget(dockForm("dock.ao"));
    aoProgress_ = new QProgressBar;
    aoProgress_->setObjectName("ao.progress");
    aoProgress_->setRange(0, 100);
    aoProgress_->setVisible(false);
    av->addWidget(aoProgress_);
    aoStatus_ = statusLabel("ao.status");
    av->addWidget(aoStatus_);
    auto* showAo = new QPushButton("Show AO");
    showAo->setObjectName("ao.show");
    showAo->setToolTip("Shows debug view 28, the sky visibility the renderer darkens with");
    connect(showAo, &QPushButton::clicked, this, [this] {
        viewSelector_->setCurrentIndex(viewSelector_->findData(kViewAo));
    });
    av->addWidget(showAo);
    av->addStretch(1);
    return addDock("Ambient Occlusion", "dock.ao", ao);
}

// Water: the plane, its optics and reflection, the waves and their animation.
QDockWidget* MainWindow::buildWaterDock() {
    auto* waterPage = new QWidget;
    auto* wv = new QVBoxLayout(waterPage);
    wv->addWidget(dockForm("dock.water"));
    waterPanel_ = new WaterPanel(doc_, viewport_);
    reportRejections(waterPanel_);
    wv->addWidget(waterPanel_);
    wv->addStretch(1);
    return addDock("Water", "dock.water", waterPage);
}

// Reflection probes: their settings and the probe inspector.
QDockWidget* MainWindow::buildReflectionDock() {
    auto* reflectionPage = new QWidget;
    auto* rv = new QVBoxLayout(reflectionPage);
    rv->addWidget(dockForm("dock.reflectionProbes"));
    reflectionPanel_ = new ReflectionPanel(doc_);
    reportRejections(reflectionPanel_);
    rv->addWidget(reflectionPanel_);
    auto* showReflection = new QPushButton("Show reflection");
    showReflection->setObjectName("reflection.show");
    showReflection->setToolTip("Shows debug view 52, the probes' specular radiance times their blend weight");
    connect(showReflection, &QPushButton::clicked, this, [this] {
        viewSelector_->setCurrentIndex(viewSelector_->findData(kViewReflectionColor));
    });
    rv->addWidget(showReflection);
    rv->addStretch(1);
    return addDock("Reflection Probes", "dock.reflectionProbes", reflectionPage);
}

// Light propagation volumes: their settings, the indirect light selector and the lights.
QDockWidget* MainWindow::buildLpvDock() {
    auto* lpvPanel = new LpvPanel(doc_);
    reportRejections(lpvPanel);
    return addDock("LPV", "dock.lpv", lpvPanel);
}

// Probe Volumes.
QDockWidget* MainWindow::buildVolumesDock() {
    auto* page = new QWidget;
    auto* v = new QVBoxLayout(page);
    v->setContentsMargins(0, 0, 0, 0);
    auto* volumes = new ProbeVolumesPanel(doc_);
    volumesPanel_ = volumes;
    reportRejections(volumes);
    v->addWidget(volumes);
    auto* inspect = new QGroupBox("Probe inspector");
    inspect->setObjectName("probeInspector.group");
    auto* iv = new QVBoxLayout(inspect);
    probeInspector_ = new ProbeInspector(doc_);
    iv->addWidget(probeInspector_);
    v->addWidget(inspect);
    v->addStretch(1);
    return addDock("Probe Volumes", "dock.probeVolumes", page);
}

// Bake & Export: the settings, the button, progress, the last report and its suggestions.
QDockWidget* MainWindow::buildBakeDock() {
    auto* bakeWidget = new QWidget;
    auto* bv = new QVBoxLayout(bakeWidget);
    auto* bf = new ParameterForm(doc_);
    bf->addParameters("bake.");
    bf->addParameters("export.");
    reportRejections(bf);
    bf->refresh();
    bv->addWidget(bf);
    outputPath_ = statusLabel("bake.outputPath");
    outputPath_->setTextInteractionFlags(Qt::TextSelectableByMouse);
    bv->addWidget(outputPath_);
    estimate_ = statusLabel("bake.estimate");
    bv->addWidget(estimate_);
    auto* buttons = new QHBoxLayout;
    bakeButton_ = new QPushButton("Bake");
    bakeButton_->setObjectName("bake.start");
    cancelButton_ = new QPushButton("Cancel");
    cancelButton_->setObjectName("bake.cancel");
    cancelButton_->setEnabled(false);
    buttons->addWidget(bakeButton_);
    buttons->addWidget(cancelButton_);
    bv->addLayout(buttons);
    progress_ = new QProgressBar;
    progress_->setObjectName("bake.progress");
    progress_->setRange(0, 100);
    progress_->setValue(0);
    bv->addWidget(progress_);
    eta_ = new QLabel;
    eta_->setObjectName("bake.eta");
    bv->addWidget(eta_);
    // The last bake's report: a row per figure, a column per volume (bake_report.json has all).
    report_ = new QTableWidget;
    report_->setObjectName("bake.report");
    report_->setEditTriggers(QAbstractItemView::NoEditTriggers);
    report_->setSelectionMode(QAbstractItemView::NoSelection);
    report_->horizontalHeader()->setSectionResizeMode(QHeaderView::Stretch);
    report_->setMinimumHeight(120);
    bv->addWidget(report_, 1);
    // What would lower a high interpolation error, with its estimated cost (the report's).
    suggestions_ = statusLabel("bake.suggestions");
    suggestions_->setTextInteractionFlags(Qt::TextSelectableByMouse);
    suggestions_->hide();
    bv->addWidget(suggestions_);
    connect(bakeButton_, &QPushButton::clicked, this, [this] { startBake(); });
    connect(cancelButton_, &QPushButton::clicked, bake_, &BakeController::cancel);
    return addDock("Bake & Export", "dock.bakeExport", bakeWidget);
}

// Trade-off: the speed/accuracy study of the bake's knobs, its points applied as edits.
QDockWidget* MainWindow::buildTradeoffDock() {
    auto* tradeoff = new TradeoffPanel(doc_);
    reportRejections(tradeoff);
    return addDock("Trade-off", "dock.tradeoff", tradeoff);
}

void MainWindow::buildDocks() {
    auto* terrainDock = buildTerrainDock();
    auto* skyDock = buildSunSkyDock();
    auto* shadowsDock = buildShadowsDock();
    auto* atmosphereDock = buildAtmosphereDock();
    auto* surfaceDock = buildSurfaceDock();
    auto* aoDock = buildAoDock();
    auto* waterDock = buildWaterDock();
    auto* reflectionDock = buildReflectionDock();
    auto* lpvDock = buildLpvDock();
    auto* volumesDock = buildVolumesDock();
    auto* bakeDock = buildBakeDock();
    auto* tradeoffDock = buildTradeoffDock();
    // Three tab groups of four, so every tab shows its whole label at the window's usual widths:
    // the ground (terrain, surface, AO, water), the light (sun and sky, shadows, atmosphere, LPV),
    // and the probes and their output.
    const std::array<std::array<QDockWidget*, 4>, 3> groups{{{terrainDock, surfaceDock, aoDock, waterDock},
                                                             {skyDock, shadowsDock, atmosphereDock, lpvDock},
                                                             {volumesDock, reflectionDock, bakeDock, tradeoffDock}}};
    for (const auto& group : groups)
        for (size_t i = 1; i < group.size(); ++i) tabifyDockWidget(group[i - 1], group[i]);
    // Whole tab labels, scrolled when the docks are narrow, rather than "Terr…" and "Wa…".
    for (auto* bar : findChildren<QTabBar*>()) {
        bar->setElideMode(Qt::ElideNone);
        bar->setUsesScrollButtons(true);
    }
    terrainDock->raise();
    skyDock->raise();
    volumesDock->raise();
    // The probe volumes' form is the longest: the lower group gets the most height.
    resizeDocks({terrainDock, skyDock, volumesDock}, {26, 32, 42}, Qt::Vertical);

    buildViewportToolbar();
    buildScenarioToolbar();
    buildStatusBar();
}

// The viewport toolbar: debug view, probe lighting and the overlays.
void MainWindow::buildViewportToolbar() {
    auto* bar = addToolBar("Viewport");
    bar->setObjectName("toolbar.viewport");
    viewSelector_ = new QComboBox;
    viewSelector_->setObjectName("viewport.debugView");
    for (const auto& v : debugViews()) {
        viewSelector_->addItem(QString("%1 %2").arg(v.number).arg(v.name), v.number);
        viewSelector_->setItemData(viewSelector_->count() - 1, QString::fromUtf8(v.shows), Qt::ToolTipRole);
    }
    bar->addWidget(new QLabel(" Debug view "));
    bar->addWidget(viewSelector_);
    probeToggle_ = new QCheckBox("Probe lighting");
    probeToggle_->setObjectName("viewport.probes");
    probeToggle_->setChecked(true);
    bar->addWidget(probeToggle_);
    auto* positions = new QCheckBox("Probe positions");
    positions->setObjectName("viewport.probePositions");
    bar->addWidget(positions);
    connect(positions, &QCheckBox::toggled, viewport_, &ViewportWindow::setProbePositions);
    // Which bounds the viewport draws (each kind on its own; View > Bounds holds the same).
    auto* boundsButton = new QToolButton;
    boundsButton->setObjectName("viewport.bounds");
    boundsButton->setText("Bounds");
    boundsButton->setToolTip("Draw the volumes' bounds over the view; click one to select it and drag its handles");
    boundsButton->setPopupMode(QToolButton::InstantPopup);
    boundsMenu_ = new QMenu("&Bounds", this);
    boundsMenu_->setObjectName("menu.bounds");
    const std::pair<BoundsKind, const char*> kinds[] = {{BoundsKind::ProbeVolume, "probeVolumes"},
                                                        {BoundsKind::ReflectionGrid, "reflectionProbes"},
                                                        {BoundsKind::LpvCascade, "lpvCascades"},
                                                        {BoundsKind::Water, "water"},
                                                        {BoundsKind::Sun, "sun"}};
    const char* titles[] = {"Probe volumes", "Reflection probes", "LPV cascades", "Water level", "Sun"};
    for (const auto& entry : kinds) {
        const BoundsKind kind = entry.first;  // a plain variable: lambdas capture it (not a binding)
        const char* name = entry.second;
        auto* a = boundsMenu_->addAction(titles[int(kind)]);
        a->setObjectName(QString("viewport.bounds.") + name);
        a->setCheckable(true);
        a->setChecked(gizmos_->shown(kind));
        connect(a, &QAction::toggled, this, [this, kind](bool on) { gizmos_->setShown(kind, on); });
    }
    boundsButton->setMenu(boundsMenu_);
    bar->addWidget(boundsButton);
    auto* leaves = new QCheckBox("Octree leaves");
    leaves->setObjectName("viewport.leaves");
    leaves->setToolTip("The leaves of adaptive volumes, bright at the minimum cell size; leaves under "
                       "6 pixels wide are left out, so zoom in to see the finest");
    bar->addWidget(leaves);
    connect(leaves, &QCheckBox::toggled, viewport_, &ViewportWindow::setLeaves);
    // The colour key of the diagnostic views, and the LPV views' scale, where the status bar
    // keeps it in sight.
    legend_ = new QLabel;
    legend_->setObjectName("status.legend");
    connect(viewSelector_, &QComboBox::currentIndexChanged, this, [this](int i) {
        viewport_->setDebugView(viewSelector_->itemData(i).toInt());
        updateLegend();
    });
    connect(probeToggle_, &QCheckBox::toggled, viewport_, &ViewportWindow::setProbeLighting);
    // Show cascades switches to the cascade view and back to the view before it; it follows the
    // selector when the view changes anywhere else.
    connect(showCascades_, &QPushButton::toggled, this, [this](bool on) {
        viewSelector_->setCurrentIndex(viewSelector_->findData(on ? kViewCascades : viewBeforeCascades_));
    });
    connect(viewSelector_, &QComboBox::currentIndexChanged, this, [this](int i) {
        const int view = viewSelector_->itemData(i).toInt();
        if (view != kViewCascades) viewBeforeCascades_ = view;
        QSignalBlocker block(showCascades_);
        showCascades_->setChecked(view == kViewCascades);
    });

}

// Lighting: which scenario the viewport shows, and a blend toward another, as an engine blends
// two baked scenarios. Shown while the project has scenarios.
void MainWindow::buildScenarioToolbar() {
    scenarioBar_ = addToolBar("Lighting");
    scenarioBar_->setObjectName("toolbar.scenarios");
    scenarioFrom_ = new QComboBox;
    scenarioFrom_->setObjectName("viewport.scenario");
    scenarioFrom_->setToolTip("The lighting scenario the viewport shows");
    scenarioTo_ = new QComboBox;
    scenarioTo_->setObjectName("viewport.scenarioTo");
    scenarioTo_->setToolTip("The scenario the slider blends toward");
    scenarioBlend_ = new QSlider(Qt::Horizontal);
    scenarioBlend_->setObjectName("viewport.scenarioBlend");
    scenarioBlend_->setRange(0, 100);
    scenarioBlend_->setMaximumWidth(140);
    scenarioBlend_->setToolTip("Blend: the probes' coefficients and the sky mix linearly, the sun turns between the two");
    scenarioBar_->addWidget(new QLabel(" Lighting "));
    scenarioBar_->addWidget(scenarioFrom_);
    scenarioBar_->addWidget(new QLabel(" blend to "));
    scenarioBar_->addWidget(scenarioTo_);
    scenarioBar_->addWidget(scenarioBlend_);
    auto changed = [this] {
        setScenarioView({scenarioFrom_->currentText().toStdString(), scenarioTo_->currentText().toStdString(),
                         float(scenarioBlend_->value()) / 100.0f});
    };
    connect(scenarioFrom_, &QComboBox::currentIndexChanged, this, changed);
    connect(scenarioTo_, &QComboBox::currentIndexChanged, this, changed);
    connect(scenarioBlend_, &QSlider::valueChanged, this, changed);
    connect(doc_, &ProjectDocument::parametersChanged, this, [this](const QString& path) {
        if (path.isEmpty() || path.startsWith("scenarios")) refreshScenarioWidgets();
    });
    refreshScenarioWidgets();
}

void MainWindow::refreshScenarioWidgets() {
    const SceneDescription& scene = doc_->project().scene;
    const std::vector<std::string> names = scenarioNames(scene);
    // A scenario renamed or removed: the view falls back to the default, as the renderer does.
    ScenarioView v{knownScenario(scene, scenarioView_.a), knownScenario(scene, scenarioView_.b), scenarioView_.blend};
    {
        const QSignalBlocker b1(scenarioFrom_), b2(scenarioTo_);
        scenarioFrom_->clear();
        scenarioTo_->clear();
        for (const std::string& n : names) {
            scenarioFrom_->addItem(QString::fromStdString(n));
            scenarioTo_->addItem(QString::fromStdString(n));
        }
    }
    scenarioBar_->setVisible(names.size() > 1);
    setScenarioView(v);
}

void MainWindow::setScenarioView(const ScenarioView& view) {
    const bool same = view.a == scenarioView_.a && view.b == scenarioView_.b && view.blend == scenarioView_.blend;
    scenarioView_ = view;
    if (scenarioFrom_) {
        const QSignalBlocker b1(scenarioFrom_), b2(scenarioTo_), b3(scenarioBlend_);
        scenarioFrom_->setCurrentText(QString::fromStdString(view.a));
        scenarioTo_->setCurrentText(QString::fromStdString(view.b));
        scenarioBlend_->setValue(int(std::lround(view.blend * 100.0f)));
        scenarioBlend_->setEnabled(view.a != view.b);
    }
    if (scenarioPanel_ && !view.blends() && scenarioPanel_->currentScenario().toStdString() != view.a) {
        const QSignalBlocker b(scenarioPanel_);
        scenarioPanel_->selectScenario(QString::fromStdString(view.a));
    }
    // The sun handle is the shown scenario's (the nearer end of a blend).
    if (gizmos_) gizmos_->setScenario(view.blend < 0.5f ? view.a : view.b);
    if (same || !renderer_) return;
    renderer_->setScenarioView(view);
    // The probes of the scenarios shown: the bake's when current, else a draft of each.
    probeSource_.clear();
    startPreview();
    viewport_->requestUpdate();
}

// The status bar: the legend, probes, frame time, the import's progress and the device.
void MainWindow::buildStatusBar() {
    frameLabel_ = new QLabel;
    frameLabel_->setObjectName("status.frame");
    probeLabel_ = new QLabel;
    probeLabel_->setObjectName("status.probes");
    sourceLabel_ = new QLabel;
    sourceLabel_->setObjectName("status.device");
    statusBar()->addWidget(legend_, 1);
    statusBar()->addPermanentWidget(probeLabel_);
    statusBar()->addPermanentWidget(frameLabel_);
    terrainBusy_ = new QProgressBar;
    terrainBusy_->setObjectName("status.terrainBusy");
    terrainBusy_->setRange(0, 0);  // busy: the import reports no fraction
    terrainBusy_->setMaximumWidth(120);
    terrainBusy_->setFormat("importing");
    terrainBusy_->setVisible(false);
    statusBar()->addPermanentWidget(terrainBusy_);
    statusBar()->addPermanentWidget(sourceLabel_);
    sourceLabel_->setText(QString::fromStdString(ctx_->deviceName()));
}

void MainWindow::buildMenus() {
    auto action = [this](QMenu* m, const QString& text, const QString& name, QKeySequence key,
                         auto slot) {
        auto* a = m->addAction(text);
        a->setObjectName(name);
        if (!key.isEmpty()) a->setShortcut(key);
        connect(a, &QAction::triggered, this, slot);
        return a;
    };
    QMenu* file = menuBar()->addMenu("&File");
    file->setObjectName("menu.file");
    action(file, "&New", "action.new", QKeySequence::New, [this] {
        if (maybeSave()) doc_->newProject();
    });
    action(file, "&Open…", "action.open", QKeySequence::Open, [this] {
        if (!maybeSave()) return;
        const QString f = QFileDialog::getOpenFileName(this, "Open project", QString(), "Terralux projects (*.json);;All files (*)");
        if (!f.isEmpty()) openProject(f);
    });
    action(file, "&Save", "action.save", QKeySequence::Save, [this] { saveInteractively(false); });
    action(file, "Save &As…", "action.saveAs", QKeySequence::SaveAs, [this] { saveInteractively(true); });
    file->addSeparator();
    action(file, "Import &DEM…", "action.importDem", QKeySequence("Ctrl+I"), [this] {
        findChild<QPushButton*>("terrain.import")->click();
    });
    action(file, "Import &HDR…", "action.importHdr", QKeySequence("Ctrl+Shift+I"), [this] {
        findChild<QPushButton*>("sky.import")->click();
    });
    action(file, "&Export to folder…", "action.export", QKeySequence("Ctrl+E"), [this] {
        const QString dir = askExportFolder();
        if (!dir.isEmpty()) startBake(dir);
    });
    recentMenu_ = file->addMenu("&Recent files");
    recentMenu_->setObjectName("menu.recent");
    connect(recentMenu_, &QMenu::aboutToShow, this, [this] {
        recentMenu_->clear();
        const QStringList files = QSettings("Terralux", "Terralux").value("recent").toStringList();
        for (const QString& f : files) {
            auto* a = recentMenu_->addAction(f);
            connect(a, &QAction::triggered, this, [this, f] {
                if (maybeSave()) openProject(f);
            });
        }
        if (files.isEmpty()) recentMenu_->addAction("(none)")->setEnabled(false);
    });
    file->addSeparator();
    action(file, "&Quit", "action.quit", QKeySequence::Quit, [this] { close(); });

    QMenu* edit = menuBar()->addMenu("&Edit");
    edit->setObjectName("menu.edit");
    QAction* undo = doc_->undoStack()->createUndoAction(this, "&Undo");
    undo->setObjectName("action.undo");
    undo->setShortcut(QKeySequence::Undo);
    // Whatever has focus, floating docks included; eventFilter keeps spin boxes from taking it.
    undo->setShortcutContext(Qt::ApplicationShortcut);
    QAction* redo = doc_->undoStack()->createRedoAction(this, "&Redo");
    redo->setObjectName("action.redo");
    redo->setShortcut(QKeySequence::Redo);
    redo->setShortcutContext(Qt::ApplicationShortcut);
    edit->addAction(undo);
    edit->addAction(redo);

    QMenu* view = menuBar()->addMenu("&View");
    view->setObjectName("menu.view");
    QMenu* views = view->addMenu("&Debug view");
    for (const auto& v : debugViews()) {
        auto* a = views->addAction(QString("%1 %2").arg(v.number).arg(v.name));
        a->setObjectName(QString("action.view.%1").arg(v.name));
        const int index = views->actions().size() - 1;
        connect(a, &QAction::triggered, this, [this, index] { viewSelector_->setCurrentIndex(index); });
    }
    view->addMenu(boundsMenu_);
    QAction* dynamic = view->addAction("D&ynamic resolution");
    dynamic->setObjectName("action.dynamicResolution");
    dynamic->setCheckable(true);
    dynamic->setChecked(viewport_->dynamicResolution());
    dynamic->setToolTip(QString("While the view changes, draw at fewer pixels to keep a frame within %1 ms; "
                                "the full resolution follows when it stops")
                            .arg(viewport_->resolution().budgetMilliseconds(), 0, 'f', 0));
    connect(dynamic, &QAction::toggled, viewport_, &ViewportWindow::setDynamicResolution);
    QMenu* panels = view->addMenu("&Panels");
    for (auto* d : findChildren<QDockWidget*>()) {
        // Menu text marks mnemonics with '&'; the title's own '&' is doubled to show as one.
        d->toggleViewAction()->setText(d->windowTitle().replace('&', "&&"));
        panels->addAction(d->toggleViewAction());
    }

    QMenu* bakeMenu = menuBar()->addMenu("&Bake");
    bakeMenu->setObjectName("menu.bake");
    action(bakeMenu, "&Bake", "action.bake", QKeySequence("Ctrl+B"), [this] { startBake(); });
    action(bakeMenu, "&Cancel", "action.cancelBake", QKeySequence("Ctrl+."), [this] { bake_->cancel(); });
}

void MainWindow::updateLegend() {
    const int view = viewSelector_->currentData().toInt();
    const auto v = findDebugView(std::to_string(view));
    if (view == kViewLpvCascade0 || view == kViewLpvAll) {
        // The LPV views show E/π over the bound volumes' light range: say which.
        const std::optional<double> range =
            viewport_->renderer() ? viewport_->renderer()->renderer().lpvViewRange() : std::nullopt;
        legend_->setText(range ? QString::fromUtf8("E/π ÷ %1 W/(m²·sr)").arg(*range, 0, 'g', 3)
                               : QString("no light in the volumes yet"));
        return;
    }
    // The key alone: after the view's title, before any note in parentheses.
    legend_->setText(v && v->needs.probeDiagnostics
                         ? QString::fromUtf8(v->shows).section(':', 1).section(" (", 0, 0).trimmed()
                         : QString());
}

void MainWindow::showError(const QString& title, const QString& message) {
    QMessageBox box(QMessageBox::Critical, title, message, QMessageBox::Ok, this);
    box.setObjectName("errorDialog");
    box.exec();
}

bool MainWindow::openProject(const QString& file) {
    QString error;
    if (!doc_->open(file, &error)) {
        showError("Open project", error);
        return false;
    }
    addRecent(file);
    return true;
}

bool MainWindow::importDemFile(const QString& file) {
    QString error;
    // The import runs on a worker; a file it cannot read reaches terrainEditFailed.
    if (doc_->importDem(file, &error)) return true;
    showError("Import DEM", error);
    return false;
}

bool MainWindow::importHdrFile(const QString& file) {
    QString error;
    if (doc_->importHdr(file, &error)) return true;
    showError("Import HDR", error);
    return false;
}

void MainWindow::addRecent(const QString& file) {
    QSettings settings("Terralux", "Terralux");
    QStringList files = settings.value("recent").toStringList();
    const QString abs = QFileInfo(file).absoluteFilePath();
    files.removeAll(abs);
    files.prepend(abs);
    while (files.size() > 8) files.removeLast();
    settings.setValue("recent", files);
}

bool MainWindow::maybeSave() {
    if (!doc_->isModified()) return true;
    QMessageBox box(QMessageBox::Warning, "Unsaved changes", "The project has unsaved changes. Save them?",
                    QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel, this);
    box.setObjectName("unsavedDialog");
    const int answer = box.exec();
    if (answer == QMessageBox::Cancel) return false;
    if (answer == QMessageBox::Save) return saveInteractively(false) && !doc_->isModified();
    return true;
}

QString MainWindow::projectFileName(const QString& chosen) {
    if (chosen.isEmpty() || chosen.endsWith(".json", Qt::CaseInsensitive)) return chosen;
    if (chosen.endsWith(".terralux", Qt::CaseInsensitive)) return chosen + ".json";
    return chosen + ".terralux.json";
}

QString MainWindow::askProjectFile(const QString& title) {
    QFileDialog dialog(this, title, QString(), "Terralux projects (*.json)");
    dialog.setObjectName("saveDialog");
    dialog.setAcceptMode(QFileDialog::AcceptSave);
    dialog.selectFile(doc_->fileName().isEmpty() ? QString("project.terralux.json") : doc_->fileName());
    if (dialog.exec() != QDialog::Accepted || dialog.selectedFiles().isEmpty()) return {};
    const QString chosen = dialog.selectedFiles().first();
    const QString file = projectFileName(chosen);
    // The dialog asked about overwriting the name typed, not the one with the suffix added.
    if (file != chosen && QFileInfo::exists(file)) {
        QMessageBox box(QMessageBox::Warning, title, QString("%1 exists. Replace it?").arg(file),
                        QMessageBox::Yes | QMessageBox::Cancel, this);
        box.setObjectName("replaceDialog");
        if (box.exec() != QMessageBox::Yes) return {};
    }
    return file;
}

bool MainWindow::saveProjectAs(const QString& chosen) {
    const QString file = projectFileName(chosen);
    QString error;
    if (!doc_->saveAs(file, &error)) {
        showError("Save As", error);
        return false;
    }
    addRecent(file);
    return true;
}

bool MainWindow::saveInteractively(bool as) {
    if (as || doc_->fileName().isEmpty()) {
        const QString file = askProjectFile(as ? "Save project as" : "Save project");
        return !file.isEmpty() && saveProjectAs(file);
    }
    QString error;
    if (doc_->save(&error)) return true;
    showError("Save", error);
    return false;
}

QString MainWindow::askExportFolder() {
    QFileDialog dialog(this, "Bake and export into");
    dialog.setObjectName("exportDialog");
    dialog.setFileMode(QFileDialog::Directory);
    dialog.setOption(QFileDialog::ShowDirsOnly);
    if (dialog.exec() != QDialog::Accepted || dialog.selectedFiles().isEmpty()) return {};
    return dialog.selectedFiles().first();
}

std::optional<std::filesystem::path> MainWindow::bakeFolder() const {
    const Project& p = doc_->project();
    const std::filesystem::path dir(p.scene.exportSettings.outDir);
    if (dir.is_absolute()) return dir.lexically_normal();
    // Untitled: a relative folder would land wherever Terralux was started from.
    if (p.file.empty()) return std::nullopt;
    return std::filesystem::absolute(p.outDir()).lexically_normal();
}

void MainWindow::updateOutputPath() {
    if (const auto dir = bakeFolder())
        outputPath_->setText("Bake writes to " + QString::fromStdString(dir->string()));
    else
        outputPath_->setText(QString("Bake writes to \"%1\" beside the project file: save the project "
                                     "first (Bake asks), or use File > Export to folder")
                                 .arg(QString::fromStdString(doc_->project().scene.exportSettings.outDir)));
}

size_t MainWindow::boundProbeCount() const { return renderer_ ? renderer_->boundProbeCount() : 0; }

bool MainWindow::event(QEvent* e) {
    if (e->type() == QEvent::ChildPolished)
        if (auto* bar = qobject_cast<QTabBar*>(static_cast<QChildEvent*>(e)->child()); bar && bar->style() != tabStyle_)
            bar->setStyle(tabStyle_);  // the dock tabs QMainWindow makes (DockTabStyle)
    return QMainWindow::event(e);
}

bool MainWindow::eventFilter(QObject* watched, QEvent* e) {
    if (e->type() == QEvent::ShortcutOverride) {
        auto* key = static_cast<QKeyEvent*>(e);
        const bool undo = key->matches(QKeySequence::Undo), redo = key->matches(QKeySequence::Redo);
        auto* w = qobject_cast<QWidget*>(watched);
        bool ours = false;
        for (QWidget* p = w; p && !ours; p = p->parentWidget()) ours = p == this;
        if ((undo || redo) && ours && documentUndoWins(w, undo)) {
            // Not overridden: the key goes to the shortcut, the document's undo or redo action.
            e->ignore();
            return true;
        }
    }
    return QMainWindow::eventFilter(watched, e);
}

void MainWindow::showReport(const nlohmann::json& report) {
    using nlohmann::json;
    struct Figure {
        const char* label;
        std::function<QString(const json&)> cell;
    };
    auto number = [](const json& v) { return v.is_number() ? QLocale().toString(v.get<double>(), 'f', 0) : QString("—"); };
    // Adaptive volumes measure interpolation error at random points; the others by their map.
    auto interpolation = [](const json& v, const char* key) {
        if (v.contains("interpolation_error")) return percent(v["interpolation_error"].value(key, json()));
        if (v.contains("error_map")) return percent(v["error_map"].value(key, json()));
        return QString("—");
    };
    const std::vector<Figure> figures = {
        {"Placement", [](const json& v) { return QString::fromStdString(v.value("placement", "")); }},
        {"Probes", [&](const json& v) { return number(v.value("probes", json())); }},
        {"Invalid (in terrain)", [&](const json& v) { return number(v.value("invalid_probes", json())); }},
        {"Rays", [&](const json& v) { return number(v.value("rays", json())); }},
        {"Rays per probe (min / median / max)",
         [&](const json& v) {
             const json& r = v.value("rays_per_probe", json::object());
             return number(r.value("min", json())) + " / " + number(r.value("median", json())) + " / " +
                    number(r.value("max", json()));
         }},
        {"Time", [](const json& v) { return QString("%1 s").arg(v.value("time_s", 0.0), 0, 'f', 2); }},
        {"File size", [](const json& v) { return formatBytes(v.value("bytes", 0.0)); }},
        {"Standard error (mean)", [](const json& v) { return percent(v["standard_error"].value("mean", json())); }},
        {"Standard error (max)", [](const json& v) { return percent(v["standard_error"].value("max", json())); }},
        {"Interpolation error (mean)", [&](const json& v) { return interpolation(v, "mean"); }},
        {"Interpolation error (p95)", [&](const json& v) { return interpolation(v, "p95"); }},
        {"Interpolation error (max)", [&](const json& v) { return interpolation(v, "max"); }},
    };
    const json& volumes = report["volumes"];
    report_->clear();
    report_->setRowCount(int(figures.size()));
    report_->setColumnCount(int(volumes.size()));
    QStringList rows, columns;
    for (const auto& f : figures) rows << f.label;
    for (const auto& v : volumes) columns << QString::fromStdString(v.value("name", ""));
    report_->setVerticalHeaderLabels(rows);
    report_->setHorizontalHeaderLabels(columns);
    // Every figure at once: the dock scrolls as a whole, the table itself should not.
    report_->setMinimumHeight(report_->horizontalHeader()->sizeHint().height() + 2 * report_->frameWidth() +
                              report_->verticalHeader()->defaultSectionSize() * report_->rowCount() +
                              (report_->horizontalScrollBar()->isVisible() ? report_->horizontalScrollBar()->height() : 0));
    for (size_t c = 0; c < volumes.size(); ++c)
        for (size_t r = 0; r < figures.size(); ++r) {
            auto* item = new QTableWidgetItem(figures[r].cell(volumes[c]));
            item->setTextAlignment(Qt::AlignRight | Qt::AlignVCenter);
            report_->setItem(int(r), int(c), item);
        }
    QString advice;
    for (const auto& v : volumes) {
        if (!v.contains("suggestions") || v["suggestions"].empty()) continue;
        advice += QString("<p><b>%1</b>: interpolation error %2 on average and %3 at p95, above %4 % or %5 %. "
                          "Denser probes lower it (measured on the same points):")
                      .arg(QString::fromStdString(v.value("name", "")))
                      .arg(percent(v["error_map"].value("mean", json())))
                      .arg(percent(v["error_map"].value("p95", json())))
                      .arg(int(std::lround(100.0 * kSuggestAboveMeanError)))
                      .arg(int(std::lround(100.0 * kSuggestAboveP95Error)));
        for (const auto& s : v["suggestions"]) {
            QStringList sets;
            for (const auto& x : s["set"]) sets << QString::fromStdString(x.get<std::string>()).toHtmlEscaped();
            advice += QString("<br>&nbsp;&nbsp;<tt>%1</tt>: %2 probes, about %3 s")
                          .arg(sets.join(", "))
                          .arg(QLocale().toString(s["probes"].get<double>(), 'f', 0))
                          .arg(s["estimated_time_s"].get<double>(), 0, 'f', 1);
            if (s["estimated_max_time_s"].get<double>() > s["estimated_time_s"].get<double>())
                advice += QString(" (up to %1 s)").arg(s["estimated_max_time_s"].get<double>(), 0, 'f', 0);
            advice += QString(", error %1 mean / %2 p95")
                          .arg(percent(s["predicted_error"].value("mean", json())))
                          .arg(percent(s["predicted_error"].value("p95", json())));
            if (!s["meets_target"].get<bool>())
                advice += QString(", short of the %1 % aimed at").arg(s["target_mean"].get<double>() * 100.0, 0, 'f', 0);
        }
        advice += "</p>";
    }
    suggestions_->setText(advice);
    suggestions_->setVisible(!advice.isEmpty());
    report_->setToolTip(QString("Total %1 rays in %2 s on %3 threads; everything is in %4")
                            .arg(QLocale().toString(report.value("rays", 0.0), 'f', 0))
                            .arg(report.value("time_s", 0.0), 0, 'f', 2)
                            .arg(report.value("threads", 0))
                            .arg(QString::fromStdString((bakeOutDir_ / "bake_report.json").string())));
}

void MainWindow::closeEvent(QCloseEvent* e) {
    if (!maybeSave()) {
        e->ignore();
        return;
    }
    QFile::remove(QDir(autosaveDir()).filePath("autosave.terralux.json"));
    e->accept();
}

void MainWindow::rebuildRenderer() {
    // A preview that finished for the terrain before may still be queued: it must not land.
    previewJob_.dismiss();
    viewport_->setRenderer(nullptr);
    stopAmbientOcclusion();
    if (makingRenderer_.valid()) {
        // The renderer being made is for the terrain before: it is retired once made.
        remakeRenderer_ = true;
        return;
    }
    if (renderer_) {
        retiredRenderer_ = std::move(renderer_);
        drain_ = ctx_->submit([](VkCommandBuffer) {});
    }
    // Built in a later turn of the event loop than the change (and than the old renderer's
    // going), once the device is done; a terrain that changes again meanwhile is built then.
    // With no renderer to retire (the first, or one retired a tick ago) it is built now.
    if (retiredRenderer_) {
        drainPoll_.start();
        return;
    }
    buildRenderer();
}

void MainWindow::buildRenderer(bool now) {
    if (now) {
        drainPoll_.stop();
        installRenderer(std::make_unique<ProjectRenderer>(*ctx_, doc_->project(), doc_->terrain(), false));
        return;
    }
    // The UI thread does no other device work meanwhile (there is no renderer to draw); the
    // worker records its uploads with a command pool of its own and shares the queue under its
    // lock (vk::WorkerCommands).
    projectChangedWhileMaking_ = false;
    remakeRenderer_ = false;
    makingRenderer_ = std::async(std::launch::async, [ctx = ctx_.get(), project = doc_->project(),
                                                      terrain = doc_->terrainShared()] {
        const BackgroundThread background;
        const vk::WorkerCommands commands(*ctx);
        return std::make_unique<ProjectRenderer>(*ctx, project, *terrain, false);
    });
    drainPoll_.start();
}

void MainWindow::installRenderer(std::unique_ptr<ProjectRenderer> made) {
    renderer_ = std::move(made);
    if (projectChangedWhileMaking_) renderer_->setProject(doc_->project());
    projectChangedWhileMaking_ = false;
    renderer_->setScenarioView(scenarioView_);
    viewport_->setCamera(renderer_->defaultCamera());
    // An untitled project with a relative output folder has no bake of its own yet.
    const auto folder = bakeFolder();
    const size_t baked = folder ? renderer_->loadProbes(false, nullptr, nullptr, *folder) : 0;
    probeSource_ = baked ? withStaleness("last bake") : QString();
    showBoundProbes();
    viewport_->setRenderer(renderer_.get());
    const Heightfield& hf = doc_->terrain().heightfield;
    const DemSourceInfo& s = doc_->terrain().source;
    const double filledShare = 100.0 * double(hf.nodataCount()) / double(hf.heights().size());
    terrainSummary_->setText(QString("%1\n%2 × %3 vertices, %4 × %5 m cells\n%6 … %7 m, %8 nodata cells filled (%10 %)\n%9")
                                 .arg(QString::fromStdString(s.path))
                                 .arg(hf.width()).arg(hf.depth())
                                 .arg(hf.cellSizeX(), 0, 'f', 2).arg(hf.cellSizeZ(), 0, 'f', 2)
                                 .arg(hf.minHeight(), 0, 'f', 1).arg(hf.maxHeight(), 0, 'f', 1)
                                 .arg(hf.nodataCount())
                                 .arg(QString::fromStdString(hf.geo.crsName.empty() ? "no CRS" : hf.geo.crsName))
                                 .arg(filledShare, 0, 'f', filledShare > 0.0 && filledShare < 0.1 ? 3 : 1));
    updateAmbientOcclusion();
    if (!baked || previewPutOff_) schedulePreview();
    previewPutOff_ = false;
    updateStatus();
}

void MainWindow::refreshLighting() {
    if (!renderer_) {
        projectChangedWhileMaking_ = true;
        return;
    }
    renderer_->setProject(doc_->project());
    albedoStatus_->setText(renderer_->albedoError().empty()
                               ? QString()
                               : "Drawn with the constant albedo: " + QString::fromStdString(renderer_->albedoError()));
    updateAmbientOcclusion();
    viewport_->requestUpdate();
}

void MainWindow::stopAmbientOcclusion() {
    aoJob_.dismiss();  // a result already queued must not land; the UI thread does not wait
    aoRunning_.reset();
    if (aoProgress_) aoProgress_->setVisible(false);
}

void MainWindow::updateAmbientOcclusion() {
    if (!renderer_) return;
    const auto wanted = renderer_->wantedAo();
    if (!wanted) {
        stopAmbientOcclusion();
        aoStatus_->setText("Off: sky and probe light are not darkened by the terrain's horizon.");
        return;
    }
    if (renderer_->aoCurrent()) {
        if (aoRunning_) stopAmbientOcclusion();
        return;
    }
    if (aoRunning_ && aoRunning_->directions == wanted->directions && aoRunning_->maxDistance == wanted->maxDistance)
        return;
    stopAmbientOcclusion();
    aoRunning_ = wanted;
    aoProgress_->setValue(0);
    aoProgress_->setVisible(true);
    aoStatus_->setText(QString("Computing %1 directions over %2 vertices…")
                           .arg(wanted->directions)
                           .arg(QLocale().toString(qulonglong(renderer_->heightfield().heights().size()))));
    auto terrain = doc_->terrainShared();
    aoJob_.startBeside([this, terrain, settings = *wanted, ctx = ctx_.get()](const LatestJob::Context& job) {
        const auto start = std::chrono::steady_clock::now();
        std::atomic<int> shown{-1};  // the progress may come from any of the AO's threads
        std::vector<float> field;
        // Its maps are built and uploaded here too: the UI thread only swaps them in.
        std::shared_ptr<TerrainRenderer::SurfaceMapTextures> maps;
        double seconds = 0.0;
        try {
            field = horizonSkyVisibility(terrain->heightfield, settings, [this, &shown, &job](double f) {
                const int percent = int(f * 100.0);
                if (shown.exchange(percent) != percent) job.post([this, percent] { aoProgress_->setValue(percent); });
                return !job.cancelled();
            });
            if (field.empty()) return;  // cancelled
            seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            const vk::WorkerCommands commands(*ctx);
            maps = std::make_shared<TerrainRenderer::SurfaceMapTextures>(
                TerrainRenderer::prepareSurfaceMaps(*ctx, terrain->heightfield, field));
        } catch (const std::exception& e) {
            job.post([this, message = QString::fromStdString(e.what())] {
                aoRunning_.reset();
                aoProgress_->setVisible(false);
                aoStatus_->setText("Not computed: " + message);
            });
            return;
        }
        job.post([this, maps, settings, seconds, vertices = field.size()] {
            if (!renderer_) return;
            renderer_->setAmbientOcclusion(settings, std::move(*maps));
            aoRunning_.reset();
            aoProgress_->setVisible(false);
            aoStatus_->setText(QString("%1 directions over %2 vertices in %3 s")
                                   .arg(settings.directions)
                                   .arg(QLocale().toString(qulonglong(vertices)))
                                   .arg(seconds, 0, 'f', 2));
            viewport_->requestUpdate();
        });
    });
}

void MainWindow::schedulePreview() { previewTimer_.start(); }

void MainWindow::startPreview() {
    // A new terrain's renderer is still to be made: it starts this preview once made.
    if (!renderer_) {
        previewPutOff_ = true;
        return;
    }
    // The project's own bake, when current, holds what a draft preview would only approximate:
    // show it (again, after an edit that was undone) and bake no preview.
    const auto folder = bakeFolder();
    if (renderer_ && folder && bakeStaleness(doc_->project(), *folder).empty()) {
        previewJob_.dismiss();  // a preview started for an edit since undone must not land
        if (probeSource_ != "last bake") {
            renderer_->setProject(doc_->project());
            renderer_->loadProbes(false, nullptr, nullptr, *folder);
            probeSource_ = withStaleness("last bake");
            showBoundProbes();
            viewport_->requestUpdate();
            updateStatus();
        }
        return;
    }
    ++previewsStarted_;
    const Project project = doc_->project();
    auto terrain = doc_->terrainShared();
    const ScenarioView shown = renderer_ ? renderer_->shownView() : ScenarioView{};
    previewJob_.startBeside([this, project, terrain, shown](const LatestJob::Context& job) {
        try {
            // The scenario shown, and the one it blends toward: a draft of each, mixed.
            Project lit = project;
            lit.scene = scenarioScene(project.scene, shown.a);
            auto preview = std::make_shared<PreviewBake>(previewBake(lit, terrain->heightfield, job.cancelFlag()));
            if (shown.blends()) {
                lit.scene = scenarioScene(project.scene, shown.b);
                const PreviewBake towards = previewBake(lit, terrain->heightfield, job.cancelFlag());
                preview->volumes = blendProbeVolumes(preview->volumes, towards.volumes, shown.blend);
            }
            job.post([this, preview] {
                if (!renderer_) return;
                renderer_->setProbes(preview->volumes);
                renderer_->setReflectionProbes(preview->reflections);
                probeSource_ = "draft preview";
                showBoundProbes();
                viewport_->requestUpdate();
                updateStatus();
            });
        } catch (const PlacementError&) {
            // Settings the bake would refuse (the Probe Volumes dock says why): light with
            // nothing rather than with the probes of settings that are gone.
            job.post([this] {
                if (!renderer_) return;
                renderer_->setProbes({});
                renderer_->setReflectionProbes(nullptr);
                probeSource_ = "no preview: placement failed";
                showBoundProbes();
                viewport_->requestUpdate();
                updateStatus();
            });
        } catch (const std::exception&) {
            // Cancelled by a newer edit.
        }
    });
}

void MainWindow::updateEstimate() {
    const Project& p = doc_->project();
    size_t probes = 0, invalid = 0, mapPoints = 0;
    uint64_t bytes = 0;
    double rays = 0;
    const BakeQuality q = qualityOf(p.scene.bake);
    // Placement errors go next to the settings they name (Probe Volumes dock) and to the status
    // bar; the estimate says it has none.
    std::vector<QString> errors(p.scene.probeVolumes.size());
    QString firstError;
    for (size_t i = 0; i < p.scene.probeVolumes.size(); ++i) {
        const auto& v = p.scene.probeVolumes[i];
        if (!v.enabled) continue;
        try {
            const auto placed = keptPlacement(p.scene, i, doc_->terrain().heightfield);
            const ProbeLayout& l = *placed;
            probes += l.validCount();
            invalid += l.positions.size() - l.validCount();
            bytes += 48 + 160ull * l.validCount() + 4ull * l.cellProbe.size();
            // A preset's target: the rays the bake plans for (its probes trace what they need).
            rays += double(l.validCount()) * volumeRays(q, v).planned();
            const size_t points = errorMapGrid(l, doc_->terrain().heightfield, p.scene.bake.errorMapResolution,
                                               errorMapHeight(v, l)).error.size();
            mapPoints += points;
            rays += double(points) * volumeRays(q, v).rays;
        } catch (const std::exception& e) {
            errors[i] = QString::fromStdString(e.what());
            if (firstError.isEmpty()) firstError = errors[i];
        }
    }
    volumesPanel_->setPlacementErrors(errors);
    if (!firstError.isEmpty()) {
        estimate_->setText("No estimate: " + firstError);
        statusBar()->showMessage(firstError, 15000);
        return;
    }
    // Cache rays plus probe rays at the throughput measured by the bake benchmark on two cores.
    const bool cached = p.scene.bake.quality != QualityPreset::Reference &&
                        (p.scene.bake.bounces ? *p.scene.bake.bounces : q.bounces) > 0;
    const std::array<int, 2> cachePoints = IrradianceCache::gridPoints(
        doc_->terrain().heightfield, cacheResolutionFor(doc_->terrain().heightfield, q, uint64_t(rays)));
    const double cacheRays =
        cached ? double(cachePoints[0]) * cachePoints[1] * (q.cacheRays + q.sunSamples) : 0.0;
    const double seconds = (rays * (p.scene.bake.quality == QualityPreset::Reference ? 8.0 : 1.5) + cacheRays) / 3.0e6;
    // Targets are chosen by trial bakes, too slow for every edit: say the figures are the settings'.
    bool targets = bool(p.scene.bake.targetError);
    for (const auto& v : p.scene.probeVolumes) targets = targets || (v.enabled && v.targetError);
    estimate_->setText(QString("Estimate: %1 probes (%2 inside the terrain), %3, %4 error-map points, about %5 s%6")
                           .arg(probes).arg(invalid).arg(formatBytes(double(bytes))).arg(mapPoints)
                           .arg(seconds, 0, 'f', 1)
                           .arg(targets ? QString(" at the settings as they stand; the bake's targets choose "
                                                  "their own (terralux --bake --dry-run shows what)")
                                        : QString()));
}

void MainWindow::updateTitle() {
    const QString name = doc_->fileName().isEmpty() ? "untitled" : QFileInfo(doc_->fileName()).fileName();
    setWindowTitle(QString("%1%2 — Terralux").arg(name, doc_->isModified() ? " *" : ""));
}

QString MainWindow::withStaleness(const QString& source) const {
    // The same test as --render: the bake's recorded inputs against the project's.
    const auto& stale = renderer_->staleBake();
    if (stale.empty()) return source;
    return source + ", stale: " + QString::fromStdString(stale.front()) +
           (stale.size() > 1 ? QString(" and %1 more").arg(stale.size() - 1) : QString());
}

void MainWindow::raiseDockOf(BoundsKind kind) {
    const char* dock = "dock.probeVolumes";
    switch (kind) {
        case BoundsKind::ProbeVolume: dock = "dock.probeVolumes"; break;
        case BoundsKind::ReflectionGrid: dock = "dock.reflectionProbes"; break;
        case BoundsKind::LpvCascade: dock = "dock.lpv"; break;
        case BoundsKind::Water: dock = "dock.water"; break;
        case BoundsKind::Sun: dock = "dock.sunSky"; break;
    }
    if (auto* d = findChild<QDockWidget*>(dock)) d->raise();
    // The dock edits the volume the viewport selected.
    if (kind == BoundsKind::ProbeVolume && gizmos_->selected()) volumesPanel_->selectVolume(gizmos_->selected()->index);
}

int MainWindow::nearestMarker(const std::vector<glm::vec3>& points, QPointF at) const {
    if (!renderer_ || viewport_->width() <= 0 || viewport_->height() <= 0) return -1;
    const ScreenProjection view(viewport_->camera(), QSizeF(viewport_->width(), viewport_->height()),
                                renderer_->heightfield());
    int best = -1;
    double bestDistance = 12.0;
    for (size_t i = 0; i < points.size(); ++i) {
        const std::optional<QPointF> screen = view.toScreen(points[i]);
        if (!screen) continue;
        const double d = std::hypot(screen->x() - at.x(), screen->y() - at.y());
        if (d < bestDistance) {
            bestDistance = d;
            best = int(i);
        }
    }
    return best;
}

std::optional<glm::vec3> MainWindow::terrainPointAt(QPointF at) const {
    if (!renderer_ || viewport_->width() <= 0 || viewport_->height() <= 0) return std::nullopt;
    const Heightfield& hf = renderer_->heightfield();
    const ScreenProjection::Ray ray =
        ScreenProjection(viewport_->camera(), QSizeF(viewport_->width(), viewport_->height()), hf).ray(at);
    if (!(ray.length > 0.0f)) return std::nullopt;
    const HeightfieldTracer tracer(hf);
    RayHit hit;
    if (!tracer.intersect(ray.origin, ray.direction, ray.length, hit)) return std::nullopt;
    return hit.position;
}

int MainWindow::reflectionProbeAt(QPointF at) const {
    if (!renderer_ || !renderer_->reflectionProbes()) return -1;
    std::vector<glm::vec3> points;
    for (const auto& p : renderer_->reflectionProbes()->probes) points.push_back(p.position);
    return nearestMarker(points, at);
}

std::optional<std::pair<int, int>> MainWindow::diffuseProbeAt(QPointF at) const {
    if (!renderer_) return std::nullopt;
    // All volumes' markers at once, so the nearest wins whichever volume holds it.
    std::vector<glm::vec3> points;
    std::vector<std::pair<int, int>> owner;
    const auto volumes = renderer_->boundVolumes();
    for (size_t v = 0; v < volumes->size(); ++v)
        if (const auto& d = (*volumes)[v].diagnostics)
            for (size_t i = 0; i < d->positions.size(); ++i) {
                points.push_back(d->positions[i]);
                owner.emplace_back(int(v), int(i));
            }
    const int hit = nearestMarker(points, at);
    if (hit < 0) return std::nullopt;
    return owner[size_t(hit)];
}

void MainWindow::showBoundProbes() {
    probeInspector_->setVolumes(renderer_ ? renderer_->boundVolumes() : nullptr, probeSource_);
    reflectionPanel_->setProbes(renderer_ ? renderer_->reflectionProbes() : nullptr, probeSource_);
}

void MainWindow::updateStatus() {
    if (!renderer_) return;
    // What the viewport holds, not what the settings would place (adaptive volumes ignore grids).
    const auto& reflections = renderer_->reflectionProbes();
    const ScenarioView shown = renderer_->shownView();
    const QString scenario =
        shown.blends() ? QString(", %1 → %2 %3 %").arg(QString::fromStdString(shown.a), QString::fromStdString(shown.b)).arg(int(std::lround(shown.blend * 100.0f)))
        : shown.a != kDefaultScenario ? QString(", scenario '%1'").arg(QString::fromStdString(shown.a))
                                      : QString();
    probeLabel_->setText(QString("%1 probes%2 (%3%4), %5 on the GPU")
                             .arg(renderer_->boundProbeCount())
                             .arg(reflections ? QString(" + %1 reflection").arg(reflections->probes.size()) : QString())
                             .arg(probeSource_.isEmpty() ? "not baked" : probeSource_)
                             .arg(scenario)
                             .arg(formatBytes(double(renderer_->renderer().probeBytes() +
                                                     renderer_->renderer().reflectionBytes()))));
}

void MainWindow::startBake(const QString& outDir) {
    if (bake_->running()) return;
    std::filesystem::path dir;
    if (!outDir.isEmpty()) {
        dir = std::filesystem::absolute(outDir.toStdString()).lexically_normal();
    } else if (const auto own = bakeFolder()) {
        dir = *own;
    } else {
        // Untitled with a relative output folder: the launch folder is no place for a bake.
        QMessageBox box(QMessageBox::Question, "Bake",
                        QString("This project has no file yet, so its output folder \"%1\" is relative to "
                                "nothing. Save the project to bake beside it, or choose a folder for this bake.")
                            .arg(QString::fromStdString(doc_->project().scene.exportSettings.outDir)),
                        QMessageBox::Cancel, this);
        box.setObjectName("bakeLocationDialog");
        QPushButton* save = box.addButton("Save Project…", QMessageBox::AcceptRole);
        save->setObjectName("bakeLocation.save");
        QPushButton* choose = box.addButton("Choose Folder…", QMessageBox::ActionRole);
        choose->setObjectName("bakeLocation.choose");
        box.exec();
        if (box.clickedButton() == save) {
            if (saveInteractively(false) && bakeFolder()) startBake();
        } else if (box.clickedButton() == choose) {
            const QString folder = askExportFolder();
            if (!folder.isEmpty()) startBake(folder);
        }
        return;
    }
    Project p = doc_->project();
    p.scene.exportSettings.outDir = dir.string();
    bakeOutDir_ = dir;
    // The last report belongs to the last bake: gone once a new one starts.
    report_->clear();
    report_->setRowCount(0);
    suggestions_->clear();
    suggestions_->hide();
    report_->setColumnCount(0);
    report_->setToolTip(QString());
    progress_->setValue(0);
    eta_->setText("starting");
    bakeButton_->setEnabled(false);
    cancelButton_->setEnabled(true);
    // The bake shows its own probes when it lands: a preview of this same project, running or
    // due, would land after it and put a draft in its place (a cancelled or failed bake asks for
    // the preview again). One asked for by a later edit lands.
    previewTimer_.stop();
    previewJob_.dismiss();
    bake_->start(p);
}

void MainWindow::autosave() {
    if (!doc_->isModified()) return;
    QDir().mkpath(autosaveDir());
    Project p = doc_->project();
    try {
        saveProject(p, QDir(autosaveDir()).filePath("autosave.terralux.json").toStdString());
        QFile source(QDir(autosaveDir()).filePath("autosave.source"));
        if (source.open(QIODevice::WriteOnly | QIODevice::Truncate)) source.write(doc_->fileName().toUtf8());
    } catch (const std::exception& e) {
        statusBar()->showMessage(QString("autosave failed: %1").arg(e.what()), 8000);
    }
}

void MainWindow::offerRecovery() {
    const QString file = QDir(autosaveDir()).filePath("autosave.terralux.json");
    if (!QFileInfo::exists(file)) return;
    QMessageBox box(QMessageBox::Question, "Recover unsaved changes",
                    QString("Terralux did not close cleanly. Recover the changes autosaved at %1?")
                        .arg(QFileInfo(file).lastModified().toString("yyyy-MM-dd hh:mm")),
                    QMessageBox::Yes | QMessageBox::No, this);
    box.setObjectName("recoveryDialog");
    if (box.exec() == QMessageBox::Yes) {
        // The project is read now; its terrain lands from the worker.
        QString error;
        if (!doc_->open(file, &error)) showError("Recover", error);
    }
    QFile::remove(file);
}

int runGui(int argc, char** argv) {
    QApplication app(argc, argv);
    QApplication::setApplicationName("Terralux");
    QApplication::setOrganizationName("Terralux");
    std::unique_ptr<MainWindow> window;
    try {
        window = std::make_unique<MainWindow>();
    } catch (const std::exception& e) {
        QMessageBox::critical(nullptr, "Terralux", QString("The viewport needs a Vulkan device: %1\n"
                                                           "Baking still works: terralux --bake --help.")
                                                       .arg(e.what()));
        return 3;
    }
    window->show();
    QMetaObject::invokeMethod(window.get(), [w = window.get()] { w->findChild<QWidget*>("viewport")->setFocus(); }, Qt::QueuedConnection);
    if (argc > 1) window->openProject(QString::fromLocal8Bit(argv[1]));
    else QMetaObject::invokeMethod(window.get(), &MainWindow::offerRecovery, Qt::QueuedConnection);
    return app.exec();
}

}  // namespace terralux
