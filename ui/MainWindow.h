#pragma once
// The authoring window: menus, the parameter docks, the live Vulkan viewport, background bakes.

#include <atomic>
#include <memory>
#include <thread>

#include <QMainWindow>
#include <QTimer>
#include <QVulkanInstance>

#include "BakeController.h"
#include "ProjectDocument.h"
#include "RenderJob.h"
#include "ViewportWindow.h"

class QComboBox;
class QLabel;
class QProgressBar;
class QPushButton;
class QPlainTextEdit;
class QMenu;
class QCheckBox;

namespace terralux {

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
    // What the viewport's probes come from: "last bake", "draft preview" or "" (none yet).
    const QString& probeSource() const { return probeSource_; }
    // Where autosaves go (TERRALUX_AUTOSAVE_DIR, else the user's data folder).
    static QString autosaveDir();
    // After an unclean exit: offers the autosaved project back.
    void offerRecovery();
    // Writes the modified project where offerRecovery finds it (a timer calls it every minute).
    void autosave();

protected:
    void closeEvent(QCloseEvent* e) override;

private:
    void buildMenus();
    void buildDocks();
    void showError(const QString& title, const QString& message);
    bool maybeSave();
    void rebuildRenderer();
    void refreshLighting();
    void schedulePreview();
    void startPreview();
    void updateEstimate();
    void updateTitle();
    void updateStatus();
    void addRecent(const QString& file);

public:
    void startBake(const QString& outDir = QString());

private:

    ProjectDocument* doc_;
    QVulkanInstance vulkan_;
    std::unique_ptr<vk::VulkanContext> ctx_;
    std::unique_ptr<ProjectRenderer> renderer_;
    ViewportWindow* viewport_ = nullptr;
    BakeController* bake_;
    QComboBox* viewSelector_ = nullptr;
    QCheckBox* probeToggle_ = nullptr;
    QLabel* estimate_ = nullptr;
    QLabel* eta_ = nullptr;
    QLabel* frameLabel_ = nullptr;
    QProgressBar* terrainBusy_ = nullptr;
    QLabel* probeLabel_ = nullptr;
    QLabel* sourceLabel_ = nullptr;
    QLabel* terrainSummary_ = nullptr;
    QProgressBar* progress_ = nullptr;
    QPushButton* bakeButton_ = nullptr;
    QPushButton* cancelButton_ = nullptr;
    QPlainTextEdit* report_ = nullptr;
    QMenu* recentMenu_ = nullptr;
    QTimer previewTimer_, autosaveTimer_;
    std::thread previewWorker_;
    std::atomic<bool> previewCancel_{false};
    unsigned previewGeneration_ = 0;
    QString probeSource_;
};

// Plain `terralux`: the window with the sample loaded (or FILE). Returns the exit code.
int runGui(int argc, char** argv);

}  // namespace terralux
