#pragma once
// The open project as the UI edits it: parameters by JSON path (the same paths as `--set`),
// every edit an undoable command, the imported terrain kept in step with terrain.*.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <QObject>
#include <QString>
#include <QUndoStack>

#include <nlohmann/json.hpp>

#include "DemImport.h"
#include "LatestJob.h"
#include "Project.h"
#include "scene/ShadowCascades.h"

namespace terralux {

class ProjectDocument : public QObject {
    Q_OBJECT
public:
    explicit ProjectDocument(QObject* parent = nullptr);

    const Project& project() const { return project_; }
    const nlohmann::json& json() const { return json_; }
    nlohmann::json value(const std::string& path) const;
    const DemImportResult& terrain() const { return *terrain_; }
    std::shared_ptr<const DemImportResult> terrainShared() const { return terrain_; }
    QUndoStack* undoStack() { return &undo_; }
    bool isModified() const { return !undo_.isClean() || dirtyOutsideUndo_; }
    QString fileName() const;  // empty for an unsaved project

    // Validates `value` at `path` and pushes it as an undoable edit. On a rule violation nothing
    // changes and `error` gets the one-line message. An edit of the terrain's DEM, scale or
    // resolution imports the DEM once, on a worker (terrainLoading); the edit lands when the
    // import succeeds, and terrainEditFailed says why when it does not (nothing changes then).
    // In manual split mode, an edit of shadows.split_mode, shadows.cascades or
    // shadows.max_distance that the authored splits no longer fit also writes fitted splits
    // (fitManualSplits, filled from the practical splits of the current view): one edit of the
    // whole shadows section.
    bool setParameter(const std::string& path, const nlohmann::json& value, QString* error);
    // Several values as one undoable edit, all validated together first: a rejected value (or
    // one that would re-import the terrain, which setParameter does on its own) changes nothing.
    // `label` names the undo step (empty: "Set" and the parameters' labels).
    bool setParameters(const std::vector<std::pair<std::string, nlohmann::json>>& values, QString* error,
                       const QString& label = {});
    // A drag in the viewport: each previewParameters validates its values as setParameters does
    // and applies them at once, not undoable (the docks and the viewport follow the pointer);
    // endLiveEdit makes everything since beginLiveEdit one undo step named `label` (none when
    // nothing changed), cancelLiveEdit puts it back as it was.
    void beginLiveEdit();
    bool previewParameters(const std::vector<std::pair<std::string, nlohmann::json>>& values, QString* error);
    void endLiveEdit(const QString& label);
    void cancelLiveEdit();
    bool liveEditing() const { return live_.has_value(); }
    // `--set` assignments ("bake.rays=128", "probe_volumes[0].grid_dims=16,16") as one edit.
    bool setAssignments(const std::vector<std::string>& assignments, QString* error);
    // The path and JSON value an assignment gives, parsed as `--set` parses it against `base`.
    // Throws ProjectError on a bad assignment.
    static std::pair<std::string, nlohmann::json> assignmentValue(const nlohmann::json& base,
                                                                   const std::string& assignment);
    bool terrainLoading() const { return loading_; }
    // Blocks (processing events) until no terrain import is running; for tests and shutdown.
    void waitForTerrain();
    // Camera moves from the viewport: stored, marked as unsaved, not undoable (like a view).
    void setCameraQuietly(const nlohmann::json& camera);
    // The viewport's width / height (16/9 until it has a size): the practical cascade splits
    // depend on it.
    void setViewAspect(double aspect);
    double viewAspect() const { return viewAspect_; }
    // The cascades of `shadows` over the project camera's view of the terrain at the view aspect,
    // as the viewport draws them.
    CascadeRange shadowRange(const ShadowSettings& shadows) const;
    CascadeRange shadowRange() const { return shadowRange(project_.scene.shadows); }

    void newProject();
    // Reads and checks the project file at once (a bad file fails here and nothing changes), then
    // imports its terrain on a worker: the project replaces the open one when its terrain is in
    // (projectOpened), or terrainEditFailed says why not (and the open project stays).
    bool open(const QString& file, QString* error);
    bool save(QString* error);
    bool saveAs(const QString& file, QString* error);
    // Imports a DEM (checked before anything changes) as an undoable edit of terrain.dem.
    bool importDem(const QString& file, QString* error);
    bool importHdr(const QString& file, QString* error);
    // Reads the raster as the terrain's albedo map (a file that cannot be read changes nothing)
    // and switches terrain.albedo_mode to map: one undoable edit.
    bool importAlbedoMap(const QString& file, QString* error);

    // Used by the undo commands: applies an already validated value (with the terrain imported
    // for it, for terrain edits).
    void apply(const std::string& path, const nlohmann::json& value,
               std::shared_ptr<DemImportResult> terrain = nullptr);
    // Applies validated values together (an intermediate state may break a rule the whole keeps).
    void apply(const std::vector<std::pair<std::string, nlohmann::json>>& values);

signals:
    void parametersChanged(const QString& path);  // "" = everything
    void terrainChanged();
    void terrainLoadingChanged(bool loading);
    void terrainEditFailed(const QString& message);
    void fileChanged();
    void projectOpened(const QString& file);
    // The camera moved or the view's aspect changed (neither is an undoable edit).
    void viewChanged();

public:
    ~ProjectDocument() override;

private:
    void startTerrainEdit(const std::string& path, nlohmann::json before, nlohmann::json after,
                          Project candidate);
    // Imports `candidate`'s terrain on the worker; `land` runs on the UI thread with it, unless a
    // newer load was started meanwhile.
    void startTerrainLoad(Project candidate, std::function<void(std::shared_ptr<DemImportResult>)> land);
    void reset(const Project& project, std::shared_ptr<DemImportResult> terrain);
    // setParameter's companion edit of shadows.splits: whether it changed `next`.
    bool fitSplits(const std::string& path, nlohmann::json& next) const;
    // The document with `values` applied, validated as a whole (throws ProjectError); `edited`
    // gets the paths the edit changes (a section where fitSplits widened it).
    nlohmann::json checkedEdit(const std::vector<std::pair<std::string, nlohmann::json>>& values,
                               std::vector<std::string>& edited) const;
    // One undo step taking `edited` from their values in `from` to those in `to`.
    void pushEdit(const std::vector<std::string>& edited, const nlohmann::json& from, const nlohmann::json& to,
                  const QString& label);
    struct LiveEdit {
        nlohmann::json before;
        std::vector<std::string> paths;
    };
    std::optional<LiveEdit> live_;
    Project project_;
    nlohmann::json json_;
    std::shared_ptr<DemImportResult> terrain_;
    QUndoStack undo_;
    bool dirtyOutsideUndo_ = false;
    double viewAspect_ = 16.0 / 9.0;
    LatestJob loader_{this};  // the terrain import
    bool loading_ = false;    // an import has started whose terrain has not landed
};

}  // namespace terralux
