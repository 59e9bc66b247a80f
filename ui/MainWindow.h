#pragma once
// The authoring window: menus, the parameter docks, the live Vulkan viewport, background bakes.

#include <atomic>
#include <filesystem>
#include <future>
#include <memory>
#include <optional>

#include <QDockWidget>
#include <QMainWindow>
#include <QTimer>
#include <QVulkanInstance>

#include "BakeController.h"
#include "LatestJob.h"
#include "ProjectDocument.h"
#include "ProjectRenderer.h"
#include "ViewportWindow.h"
#include "VolumeHandles.h"

class QComboBox;
class QLabel;
class QProgressBar;
class QPushButton;
class QProxyStyle;
class QTableWidget;
class QMenu;
class QCheckBox;
class QSlider;
class QToolBar;

namespace terralux {

class ParameterForm;
class ProbeVolumesPanel;
class WaterPanel;
class ReflectionPanel;
class ProbeInspector;
class ViewportGizmos;
class ScenarioPanel;

class MainWindow : public QMainWindow {
    Q_OBJECT
public:
    // Throws vk::VulkanUnavailable when no Vulkan device can present (the caller says so plainly).
    explicit MainWindow(QWidget* parent = nullptr);
    ~MainWindow() override;

    ProjectDocument* document() { return doc_; }
    ViewportWindow* viewport() { return viewport_; }
    BakeController* bakes() { return bake_; }
    // Opens a project or shows the error dialog; for the command line and tests.
    bool openProject(const QString& file);
    // Imports a DEM or HDR as File > Import does after its file dialog: an error dialog on failure.
    bool importDemFile(const QString& file);
    bool importHdrFile(const QString& file);
    // What the viewport's probes come from: "last bake" (the project's output folder),
    // "export in <folder>" (a bake written elsewhere), "draft preview" or "" (none yet).
    const QString& probeSource() const { return probeSource_; }
    // Which lighting scenario the viewport shows, or the blend of two (the toolbar's Lighting
    // switch and slider; selecting a scenario in the Sun & Sky dock shows it).
    const ScenarioView& scenarioView() const { return scenarioView_; }
    void setScenarioView(const ScenarioView& view);
    // The reflection probe whose marker is nearest to `at` (viewport pixels), within 12 pixels;
    // -1 when none (or no reflection probes are bound).
    int reflectionProbeAt(QPointF at) const;
    // The diffuse probe (bound volume, record) whose marker is nearest to `at`, within 12
    // pixels; nullopt when none (or the bound volumes carry no positions).
    std::optional<std::pair<int, int>> diffuseProbeAt(QPointF at) const;
    ProbeInspector* probeInspector() { return probeInspector_; }
    // The volumes' bounds and handles drawn over the viewport.
    ViewportGizmos* gizmos() { return gizmos_; }
    // The terrain point under `at` (viewport pixels): the pixel's ray traced against the
    // heightfield; nullopt over the sky.
    std::optional<glm::vec3> terrainPointAt(QPointF at) const;
    // Probes the viewport lights with now (the bound preview or bake).
    size_t boundProbeCount() const;
    // Draft previews started so far: edits that change no probes start none.
    unsigned previewsStarted() const { return previewsStarted_; }
    // Renderers made on a worker (every one after the window's first).
    unsigned renderersMadeOnWorkers() const { return renderersMadeOnWorkers_; }
    // Retired renderers torn down on a worker (all of them but the last, at close).
    unsigned renderersTornDownOnWorkers() const { return renderersTornDownOnWorkers_.load(); }
    // The absolute folder Bake writes: export.out_dir, relative to the project file. None for an
    // untitled project with a relative out_dir (Bake asks to save it or for a folder).
    std::optional<std::filesystem::path> bakeFolder() const;
    // A project file name as saved: a name not ending in .json gets ".terralux.json" (".json"
    // after ".terralux"), so File > Open lists it.
    static QString projectFileName(const QString& chosen);
    // Saves to `chosen` (with projectFileName's suffix) or shows the error dialog.
    bool saveProjectAs(const QString& chosen);
    // Where autosaves go (TERRALUX_AUTOSAVE_DIR, else the user's data folder).
    static QString autosaveDir();
    // After an unclean exit: offers the autosaved project back.
    void offerRecovery();
    // Writes the modified project where offerRecovery finds it (a timer calls it every minute).
    void autosave();

protected:
    void closeEvent(QCloseEvent* e) override;
    bool event(QEvent* e) override;
    bool eventFilter(QObject* watched, QEvent* e) override;

private:
    void buildMenus();
    void buildDocks();  // the docks below, tabbed, then the toolbar and the status bar
    QDockWidget* buildTerrainDock();
    QDockWidget* buildSunSkyDock();
    QDockWidget* buildShadowsDock();
    QDockWidget* buildAtmosphereDock();
    QDockWidget* buildSurfaceDock();
    QDockWidget* buildAoDock();
    QDockWidget* buildWaterDock();
    QDockWidget* buildReflectionDock();
    QDockWidget* buildLpvDock();
    QDockWidget* buildVolumesDock();
    QDockWidget* buildBakeDock();
    QDockWidget* buildTradeoffDock();
    void buildViewportToolbar();
    void buildStatusBar();
    // `w` scrolled in a dock on the right, titled `title`, named `name`.
    QDockWidget* addDock(const QString& title, const QString& name, QWidget* w);
    // A form of the rows of one dock of the parameter table (parameterDock), in table order.
    ParameterForm* dockForm(const std::string& dockName);
    // A panel's rejected edits go to the status bar.
    template <class Panel>
    void reportRejections(Panel* panel) {
        connect(panel, &Panel::rejected, this, &MainWindow::showRejection);
    }
    void showRejection(const QString& message);
    void showError(const QString& title, const QString& message);
    bool maybeSave();
    // File > Save (as = false: only asks for a name when untitled) and Save As.
    bool saveInteractively(bool as);
    QString askProjectFile(const QString& title);
    QString askExportFolder();
    void showReport(const nlohmann::json& report);
    void updateOutputPath();
    // A new terrain's renderer. The one it replaces is kept until the device has finished its
    // frames (a CPU device takes hundreds of milliseconds over one): the new renderer's uploads
    // share the queue and would wait behind them on the UI thread.
    void rebuildRenderer();
    // Makes the document's renderer: on a worker (N42E001's took the UI thread 350 ms to make),
    // installed by drainPoll_ once made; `now`: here (the window's first, before it is shown).
    void buildRenderer(bool now = false);
    // What follows making a renderer: the bake it draws, the camera, the viewport, the summary.
    void installRenderer(std::unique_ptr<ProjectRenderer> made);
    bool tearingDown() const;  // a retired renderer's teardown is still running on its worker
    void refreshLighting();
    // Starts the horizon AO the project asks for on a worker, unless the renderer has it or it
    // is under way; the result lands in the renderer on the UI thread.
    void updateAmbientOcclusion();
    void stopAmbientOcclusion();
    void schedulePreview();
    void startPreview();
    void updateEstimate();
    void updateTitle();
    void updateStatus();
    // The probe panels (reflection and diffuse inspectors) show what the renderer has bound.
    void showBoundProbes();
    // Index of the point whose projection is nearest to `at` within 12 pixels, or -1.
    int nearestMarker(const std::vector<glm::vec3>& points, QPointF at) const;
    // Brings the dock that edits what `kind` bounds to the front.
    void raiseDockOf(BoundsKind kind);
    // "last bake" or "last bake, stale: <what differs>" for the bake the renderer just loaded.
    QString withStaleness(const QString& source) const;
    void addRecent(const QString& file);

public:
    void startBake(const QString& outDir = QString());

private:

    ProjectDocument* doc_;
    QVulkanInstance vulkan_;
    std::unique_ptr<vk::VulkanContext> ctx_;
    // The renderer a new terrain replaced, until drain_ (an empty submission behind its frames)
    // has passed; drainPoll_ asks meanwhile.
    std::unique_ptr<ProjectRenderer> retiredRenderer_;
    vk::Submission drain_;
    // A drained renderer's teardown, on a worker: it frees its copies of the terrain and its
    // buffers (a 16 384² grid's took 100 ms). Meanwhile the UI thread records nothing with the
    // context's command pool, whose buffers the teardown may free: no renderer is installed
    // until it has finished.
    std::future<void> tearingDown_;
    QTimer drainPoll_;
    // The renderer being made on a worker (buildRenderer), for a terrain that a newer one may
    // have replaced meanwhile (remakeRenderer_: it is retired unshown and made again).
    std::future<std::unique_ptr<ProjectRenderer>> makingRenderer_;
    bool remakeRenderer_ = false;
    bool projectChangedWhileMaking_ = false;  // an edit the renderer being made has not seen
    unsigned renderersMadeOnWorkers_ = 0;
    std::atomic<unsigned> renderersTornDownOnWorkers_{0};
    bool previewPutOff_ = false;  // a preview asked for while no renderer was there
    std::unique_ptr<ProjectRenderer> renderer_;
    ViewportWindow* viewport_ = nullptr;
    BakeController* bake_;
    QComboBox* viewSelector_ = nullptr;
    QCheckBox* probeToggle_ = nullptr;
    QPushButton* showCascades_ = nullptr;
    int viewBeforeCascades_ = 0;  // the view Show cascades goes back to
    QLabel* estimate_ = nullptr;
    QLabel* eta_ = nullptr;
    QLabel* frameLabel_ = nullptr;
    QLabel* legend_ = nullptr;  // status.legend: the key of the diagnostic views, the LPV views' scale
    void updateLegend();
    QProgressBar* terrainBusy_ = nullptr;
    QLabel* probeLabel_ = nullptr;
    QLabel* sourceLabel_ = nullptr;
    QLabel* terrainSummary_ = nullptr;
    QProgressBar* progress_ = nullptr;
    QPushButton* bakeButton_ = nullptr;
    QPushButton* cancelButton_ = nullptr;
    QTableWidget* report_ = nullptr;
    QLabel* suggestions_ = nullptr;
    QLabel* outputPath_ = nullptr;
    ProbeVolumesPanel* volumesPanel_ = nullptr;
    WaterPanel* waterPanel_ = nullptr;
    ReflectionPanel* reflectionPanel_ = nullptr;
    ProbeInspector* probeInspector_ = nullptr;
    ViewportGizmos* gizmos_ = nullptr;
    QMenu* boundsMenu_ = nullptr;
    QProxyStyle* tabStyle_ = nullptr;
    std::filesystem::path bakeOutDir_;  // where the running (or last) bake writes
    QMenu* recentMenu_ = nullptr;
    QTimer previewTimer_, autosaveTimer_;
    LatestJob previewJob_{this};  // the draft preview bake
    LatestJob aoJob_{this};       // the horizon AO
    std::optional<HorizonAoSettings> aoRunning_;  // the settings the worker computes
    QProgressBar* aoProgress_ = nullptr;
    QLabel* aoStatus_ = nullptr;
    QLabel* albedoStatus_ = nullptr;
    unsigned previewsStarted_ = 0;
    QString probeSource_;
    // Lighting scenarios: the dock's list, the viewport's switch and blend, and what it shows.
    ScenarioPanel* scenarioPanel_ = nullptr;
    QToolBar* scenarioBar_ = nullptr;
    QComboBox *scenarioFrom_ = nullptr, *scenarioTo_ = nullptr;
    QSlider* scenarioBlend_ = nullptr;
    ScenarioView scenarioView_;
    void buildScenarioToolbar();
    void refreshScenarioWidgets();
};

// Plain `terralux`: the window with the sample loaded (or FILE). Returns the exit code.
int runGui(int argc, char** argv);

}  // namespace terralux
