#pragma once
// Dock panels that edit project parameters by JSON path. Every row's editor is named
// "param.<path>" (e.g. "param.sun.elevation_deg", "param.volume.grid_dims.0"), so Qt Test suites
// can find it; docs/UI_OBJECT_NAMES.md lists them all.

#include <functional>
#include <string>
#include <vector>

#include <QWidget>

#include <nlohmann/json.hpp>

class QFormLayout;
class QListWidget;
class QLabel;

namespace terralux {

class ProjectDocument;

// A form whose rows read and write document parameters. `prefix` is prepended to the paths of
// rows added with a relative path (the probe-volume rows use "probe_volumes[i].").
class ParameterForm : public QWidget {
    Q_OBJECT
public:
    ParameterForm(ProjectDocument* doc, QWidget* parent = nullptr);
    void setPrefix(const std::string& prefix) { prefix_ = prefix; refresh(); }
    // Object names become "param.<namePrefix><path>"; set before adding rows.
    void setNamePrefix(const std::string& p) { namePrefix_ = p; }

    void addNumber(const std::string& path, const QString& label, double min, double max,
                   int decimals, const QString& unit, bool slider = false);
    void addInteger(const std::string& path, const QString& label, int min, int max,
                    const QString& nullText = QString());  // nullText: min means null
    void addOptionalNumber(const std::string& path, const QString& label, double max, int decimals,
                           const QString& unit, const QString& nullText);
    void addIntegerArray(const std::string& path, const QString& label, int count, int min, int max);
    void addBool(const std::string& path, const QString& label);
    void addChoice(const std::string& path, const QString& label, const QStringList& choices);
    void addColor(const std::string& path, const QString& label);
    void addText(const std::string& path, const QString& label);
    void addWidget(const QString& label, QWidget* w);

    void refresh();

signals:
    void rejected(const QString& message);

protected:
    void showEvent(QShowEvent* e) override;

private:
    std::string full(const std::string& path) const { return prefix_ + path; }
    QString objectNameFor(const std::string& path) const;
    void set(const std::string& path, const nlohmann::json& value);
    ProjectDocument* doc_;
    QFormLayout* form_;
    std::string prefix_, namePrefix_;
    std::vector<std::function<void()>> refreshers_;
};

// Probe Volumes: the list of volumes (add, remove, rename) and the selected volume's settings.
class ProbeVolumesPanel : public QWidget {
    Q_OBJECT
public:
    ProbeVolumesPanel(ProjectDocument* doc, QWidget* parent = nullptr);
    int currentVolume() const;
    void selectVolume(int index);

signals:
    void rejected(const QString& message);

private:
    void refresh();
    void editVolumes(const std::function<void(nlohmann::json&)>& edit, const QString& what);
    ProjectDocument* doc_;
    QListWidget* list_;
    ParameterForm* form_;
};

}  // namespace terralux
