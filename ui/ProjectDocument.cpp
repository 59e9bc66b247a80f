#include "ProjectDocument.h"

#include <algorithm>

#include <QFileInfo>
#include <QUndoCommand>

#include <QCoreApplication>
#include <QThread>

#include "ParameterTable.h"
#include "SceneLighting.h"
#include "TerrainLoading.h"

namespace terralux {

namespace {

// One parameter edit: the JSON value before and after, by path.
class SetParameterCommand : public QUndoCommand {
public:
    SetParameterCommand(ProjectDocument* doc, std::string path, nlohmann::json before,
                        nlohmann::json after)
        : QUndoCommand(QString::fromStdString("Set " + editLabel(path, doc->json()))), doc_(doc),
          path_(std::move(path)), before_(std::move(before)), after_(std::move(after)) {}
    void undo() override { doc_->apply(path_, before_); }
    void redo() override { doc_->apply(path_, after_); }

private:
    ProjectDocument* doc_;
    std::string path_;
    nlohmann::json before_, after_;
};

// An edit that changes the terrain: it keeps both imported terrains, so undo and redo never
// import again.
class SetTerrainCommand : public QUndoCommand {
public:
    SetTerrainCommand(ProjectDocument* doc, std::string path, nlohmann::json before, nlohmann::json after,
                      std::shared_ptr<DemImportResult> terrainBefore, std::shared_ptr<DemImportResult> terrainAfter)
        : QUndoCommand(QString::fromStdString("Set " + editLabel(path, doc->json()))), doc_(doc),
          path_(std::move(path)), before_(std::move(before)), after_(std::move(after)),
          terrainBefore_(std::move(terrainBefore)),
          terrainAfter_(std::move(terrainAfter)) {}
    void undo() override { doc_->apply(path_, before_, terrainBefore_); }
    void redo() override { doc_->apply(path_, after_, terrainAfter_); }

private:
    ProjectDocument* doc_;
    std::string path_;
    nlohmann::json before_, after_;
    std::shared_ptr<DemImportResult> terrainBefore_, terrainAfter_;
};

// Several parameters in one step (setParameters): applied together, undone together.
class SetParametersCommand : public QUndoCommand {
public:
    using Values = std::vector<std::pair<std::string, nlohmann::json>>;
    SetParametersCommand(ProjectDocument* doc, const QString& text, Values before, Values after)
        : QUndoCommand(text), doc_(doc), before_(std::move(before)), after_(std::move(after)) {}
    void undo() override { doc_->apply(before_); }
    void redo() override { doc_->apply(after_); }

private:
    ProjectDocument* doc_;
    Values before_, after_;
};

// Edits the parameter table marks as re-importing the DEM (or a whole section holding one).
bool touchesTerrain(const std::string& path) {
    if (path.empty()) return true;
    if (const ParameterSpec* spec = findParameter(path)) return (spec->invalidates & kReimport) != 0;
    for (const auto& spec : parameterTable())
        if ((spec.invalidates & kReimport) && spec.path.rfind(path + ".", 0) == 0) return true;
    return false;
}

// The JSON value at a `--set` path ("probe_volumes[0].grid_dims"), through its JSON pointer
// ("/probe_volumes/0/grid_dims"); null when absent.
nlohmann::json at(const nlohmann::json& doc, const std::string& path) {
    std::string pointer;
    for (char c : path) {
        if (c == '.' || c == '[') pointer += '/';
        else if (c != ']') pointer += c;
    }
    const nlohmann::json::json_pointer p(pointer.empty() || pointer[0] == '/' ? pointer : "/" + pointer);
    return doc.contains(p) ? doc.at(p) : nlohmann::json();
}

}  // namespace

ProjectDocument::ProjectDocument(QObject* parent) : QObject(parent) {
    connect(&undo_, &QUndoStack::cleanChanged, this, [this] { emit fileChanged(); });
    newProject();
}

QString ProjectDocument::fileName() const { return QString::fromStdString(project_.file.string()); }

nlohmann::json ProjectDocument::value(const std::string& path) const { return at(json_, path); }

void ProjectDocument::reset(const Project& project, std::shared_ptr<DemImportResult> terrain) {
    project_ = project;
    json_ = projectToJson(project_);
    terrain_ = std::move(terrain);
    undo_.clear();
    undo_.setClean();
    dirtyOutsideUndo_ = false;
    emit terrainChanged();
    emit parametersChanged(QString());
    emit fileChanged();
}

void ProjectDocument::newProject() {
    Project p;
    reset(p, std::make_shared<DemImportResult>(loadProjectTerrain(p)));
}

bool ProjectDocument::open(const QString& file, QString* error) {
    try {
        Project p = loadProject(file.toStdString(), nullptr);
        startTerrainLoad(p, [this, p, file](std::shared_ptr<DemImportResult> terrain) {
            reset(p, std::move(terrain));
            emit projectOpened(file);
        });
        return true;
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        return false;
    }
}

bool ProjectDocument::save(QString* error) {
    if (project_.file.empty()) {
        if (error) *error = "the project has no file name yet: use Save As";
        return false;
    }
    return saveAs(fileName(), error);
}

bool ProjectDocument::saveAs(const QString& file, QString* error) {
    try {
        const std::filesystem::path target = std::filesystem::absolute(file.toStdString());
        Project toSave = project_;
        // An untitled project's relative output folder ("bake") means beside the project once it
        // has a file, not beside the folder Terralux was started from.
        std::string& out = toSave.scene.exportSettings.outDir;
        if (project_.file.empty() && std::filesystem::path(out).is_relative())
            out = (target.parent_path() / out).lexically_normal().string();
        saveProject(toSave, target);
        // Relative paths now resolve against the new folder.
        Project reloaded = loadProject(target, nullptr);
        project_ = reloaded;
        json_ = projectToJson(project_);
        undo_.setClean();
        dirtyOutsideUndo_ = false;
        emit fileChanged();
        emit parametersChanged(QString());
        return true;
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        return false;
    }
}

bool ProjectDocument::setParameter(const std::string& path, const nlohmann::json& value,
                                   QString* error) {
    try {
        nlohmann::json next = json_;
        applyOverride(next, path + "=" + value.dump());
        const std::string edited = fitSplits(path, next) ? std::string("shadows") : path;
        Project candidate = project_;
        candidate.scene = sceneFromJson(next, "project", nullptr);
        const nlohmann::json before = at(json_, edited);
        if (before == at(next, edited)) return true;
        if (touchesTerrain(edited)) {
            startTerrainEdit(edited, before, at(next, edited), candidate);
            return true;
        }
        if (terrain_) checkSunPlaces(candidate.scene, terrain_->heightfield);  // a place the DEM can give
        undo_.push(new SetParameterCommand(this, edited, before, at(next, edited)));
        return true;
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        return false;
    }
}

nlohmann::json ProjectDocument::checkedEdit(const std::vector<std::pair<std::string, nlohmann::json>>& values,
                                            std::vector<std::string>& edited) const {
    nlohmann::json next = json_;
    for (const auto& [path, value] : values) {
        applyOverride(next, path + "=" + value.dump());
        const std::string e = fitSplits(path, next) ? std::string("shadows") : path;
        if (touchesTerrain(e))
            throw ProjectError(e + ": a terrain edit re-imports the DEM and is made on its own");
        if (std::find(edited.begin(), edited.end(), e) == edited.end()) edited.push_back(e);
    }
    Project candidate = project_;
    candidate.scene = sceneFromJson(next, "project", nullptr);
    if (terrain_) checkSunPlaces(candidate.scene, terrain_->heightfield);
    return next;
}

void ProjectDocument::pushEdit(const std::vector<std::string>& edited, const nlohmann::json& from,
                               const nlohmann::json& to, const QString& label) {
    SetParametersCommand::Values before, after;
    QStringList names;
    for (const std::string& e : edited) {
        if (at(from, e) == at(to, e)) continue;
        before.emplace_back(e, at(from, e));
        after.emplace_back(e, at(to, e));
        names << QString::fromStdString(editLabel(e, from));
    }
    if (after.empty()) return;
    // Undo restores in reverse, so a section and a path inside it land as they were.
    std::reverse(before.begin(), before.end());
    undo_.push(new SetParametersCommand(this, label.isEmpty() ? "Set " + names.join(", ") : label, std::move(before),
                                        std::move(after)));
}

bool ProjectDocument::setParameters(const std::vector<std::pair<std::string, nlohmann::json>>& values,
                                    QString* error, const QString& label) {
    try {
        std::vector<std::string> edited;
        const nlohmann::json next = checkedEdit(values, edited);
        pushEdit(edited, json_, next, label);
        return true;
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        return false;
    }
}

void ProjectDocument::beginLiveEdit() {
    live_ = LiveEdit{json_, {}};
}

bool ProjectDocument::previewParameters(const std::vector<std::pair<std::string, nlohmann::json>>& values,
                                        QString* error) {
    if (!live_) beginLiveEdit();
    try {
        std::vector<std::string> edited;
        (void)checkedEdit(values, edited);
        for (const std::string& e : edited)
            if (std::find(live_->paths.begin(), live_->paths.end(), e) == live_->paths.end()) live_->paths.push_back(e);
        apply(values);
        return true;
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        return false;
    }
}

void ProjectDocument::endLiveEdit(const QString& label) {
    if (!live_) return;
    const LiveEdit live = std::move(*live_);
    live_.reset();
    pushEdit(live.paths, live.before, json_, label);
}

void ProjectDocument::cancelLiveEdit() {
    if (!live_) return;
    const LiveEdit live = std::move(*live_);
    live_.reset();
    std::vector<std::pair<std::string, nlohmann::json>> before;
    for (const std::string& e : live.paths) before.emplace_back(e, at(live.before, e));
    if (!before.empty()) apply(before);
}

std::pair<std::string, nlohmann::json> ProjectDocument::assignmentValue(const nlohmann::json& base,
                                                                         const std::string& assignment) {
    nlohmann::json next = base;
    applyOverride(next, assignment);  // throws on a malformed assignment, so '=' is there
    const std::string path = assignment.substr(0, assignment.find('='));
    return {path, at(next, path)};
}

bool ProjectDocument::setAssignments(const std::vector<std::string>& assignments, QString* error) {
    std::vector<std::pair<std::string, nlohmann::json>> values;
    try {
        // Each against the values before it, as `--set` applies them in order.
        nlohmann::json next = json_;
        for (const std::string& a : assignments) {
            values.push_back(assignmentValue(next, a));
            applyOverride(next, a);
        }
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        return false;
    }
    return setParameters(values, error);
}

ProjectDocument::~ProjectDocument() = default;  // the loader waits for its import

void ProjectDocument::startTerrainEdit(const std::string& path, nlohmann::json before,
                                       nlohmann::json after, Project candidate) {
    startTerrainLoad(std::move(candidate), [this, path, before = std::move(before),
                                            after = std::move(after)](std::shared_ptr<DemImportResult> terrain) {
        undo_.push(new SetTerrainCommand(this, path, before, after, terrain_, std::move(terrain)));
    });
}

void ProjectDocument::startTerrainLoad(Project candidate,
                                       std::function<void(std::shared_ptr<DemImportResult>)> land) {
    // An earlier import's result is superseded (an import is not cancelled: it is waited for).
    loading_ = true;
    emit terrainLoadingChanged(true);
    loader_.start([this, candidate = std::move(candidate), land = std::move(land)](const LatestJob::Context& job) {
        std::shared_ptr<DemImportResult> terrain;
        QString error;
        try {
            terrain = std::make_shared<DemImportResult>(loadProjectTerrain(candidate));
            // A date-and-time sun needs the new DEM to say where it is (or a place set by hand).
            checkSunPlaces(candidate.scene, terrain->heightfield);
        } catch (const std::exception& e) {
            error = QString::fromStdString(e.what());
        }
        job.post([this, terrain, error, land] {
            loading_ = false;
            emit terrainLoadingChanged(false);
            if (!terrain) {
                emit terrainEditFailed(error);
                return;
            }
            land(terrain);
        });
    });
}

void ProjectDocument::waitForTerrain() {
    while (terrainLoading()) {
        QCoreApplication::processEvents(QEventLoop::AllEvents, 20);
        QThread::msleep(5);
    }
}

void ProjectDocument::apply(const std::string& path, const nlohmann::json& value,
                            std::shared_ptr<DemImportResult> terrain) {
    applyOverride(json_, path + "=" + value.dump());
    project_.scene = sceneFromJson(json_, "project", nullptr);
    if (terrain) {
        terrain_ = std::move(terrain);
        emit terrainChanged();
    }
    emit parametersChanged(QString::fromStdString(path));
}

void ProjectDocument::apply(const std::vector<std::pair<std::string, nlohmann::json>>& values) {
    for (const auto& [path, value] : values) applyOverride(json_, path + "=" + value.dump());
    project_.scene = sceneFromJson(json_, "project", nullptr);
    for (const auto& v : values) emit parametersChanged(QString::fromStdString(v.first));
}

void ProjectDocument::setCameraQuietly(const nlohmann::json& camera) {
    // Merged, so that settings the viewport does not move (exposure) stay.
    json_["camera"].update(camera);
    project_.scene = sceneFromJson(json_, "project", nullptr);
    dirtyOutsideUndo_ = true;
    emit fileChanged();
    emit viewChanged();
}

void ProjectDocument::setViewAspect(double aspect) {
    if (!(aspect > 0.0) || aspect == viewAspect_) return;
    viewAspect_ = aspect;
    emit viewChanged();
}

CascadeRange ProjectDocument::shadowRange(const ShadowSettings& shadows) const {
    const Heightfield& hf = terrain_->heightfield;
    const glm::vec3 lo(hf.minX(), hf.minHeight(), hf.minZ()), hi(hf.maxX(), hf.maxHeight(), hf.maxZ());
    return cascadeRange(shadows, OrbitCamera::fromSettings(project_.scene.camera, hf), float(viewAspect_), lo, hi);
}

bool ProjectDocument::fitSplits(const std::string& path, nlohmann::json& next) const {
    if (path != "shadows.split_mode" && path != "shadows.cascades" && path != "shadows.max_distance") return false;
    nlohmann::json& shadows = next["shadows"];
    if (shadows.value("split_mode", "") != "manual") return false;
    // The section as practical mode reads it, for the count, the distance and the practical splits;
    // a value it rejects stays rejected by the edit itself.
    nlohmann::json practical = next;
    practical["shadows"]["split_mode"] = "practical";
    practical["shadows"]["splits"] = nullptr;
    ShadowSettings s;
    try {
        s = sceneFromJson(practical, "project", nullptr).shadows;
    } catch (const std::exception&) {
        return false;
    }
    if (s.cascades < 2) return false;
    const nlohmann::json& authored = shadows["splits"];
    std::vector<double> current;
    if (authored.is_array())
        for (const auto& d : authored)
            if (d.is_number()) current.push_back(d.get<double>());
    const std::vector<double> fitted = fitManualSplits(current, s.cascades, shadowRange(s), s.maxDistance);
    if (fitted == current) return false;
    shadows["splits"] = fitted;
    return true;
}

bool ProjectDocument::importDem(const QString& file, QString* error) {
    const std::string abs = std::filesystem::absolute(file.toStdString()).lexically_normal().string();
    return setParameter("terrain.dem", abs, error);
}

bool ProjectDocument::importHdr(const QString& file, QString* error) {
    const std::string abs = std::filesystem::absolute(file.toStdString()).lexically_normal().string();
    try {
        // Read and filter it once, before anything changes: a bad file fails here, and the
        // sky cache hands the same environment to the renderer and the preview.
        Project candidate = project_;
        candidate.scene.sky.mode = SkyMode::Hdr;
        candidate.scene.sky.hdr = abs;
        (void)skyOf(candidate, terrain_->heightfield);
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        return false;
    }
    undo_.beginMacro("Import HDR");
    const bool ok = setParameter("sky.hdr", abs, error) && setParameter("sky.mode", "hdr", error);
    undo_.endMacro();
    return ok;
}

bool ProjectDocument::importAlbedoMap(const QString& file, QString* error) {
    const std::string abs = std::filesystem::absolute(file.toStdString()).lexically_normal().string();
    try {
        Project candidate = project_;
        candidate.scene.terrain.albedoMode = AlbedoMode::Map;
        candidate.scene.terrain.albedoMap = abs;
        (void)surfaceAlbedoOf(candidate, terrain_->heightfield);
    } catch (const std::exception& e) {
        if (error) *error = QString::fromStdString(e.what());
        return false;
    }
    undo_.beginMacro("Import albedo map");
    const bool ok = setParameter("terrain.albedo_map", abs, error) && setParameter("terrain.albedo_mode", "map", error);
    undo_.endMacro();
    return ok;
}

}  // namespace terralux
