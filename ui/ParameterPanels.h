#pragma once
// Dock panels that edit project parameters by JSON path. Every row's editor is named by
// uiObjectName (e.g. "param.sun.elevation_deg", "param.volume.grid_dims.0"), so Qt Test suites
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
struct ParameterSpec;

// A form whose rows read and write document parameters, built from the parameter table.
class ParameterForm : public QWidget {
    Q_OBJECT
public:
    ParameterForm(ProjectDocument* doc, QWidget* parent = nullptr);
    // Per-volume rows edit probe_volumes[volume], per-light rows lights[index].
    void setVolume(int volume) { setElement(volume); }
    void setElement(int index);
    int element() const { return element_; }

    // The editor of one row of the parameter table (app/ParameterTable.h): its widget, limits,
    // unit, "auto" text and tooltip all come from the row. `path` is the table's path
    // ("sun.elevation_deg", "probe_volumes[].grid_dims").
    void addParameter(const std::string& path);
    // Every UI row of the table whose path starts with `prefix`, in table order.
    void addParameters(const std::string& prefix);
    void addWidget(const QString& label, QWidget* w);
    // A row of its own across the label and field columns.
    void addWidget(QWidget* w);

    void refresh();
    // Marks the rows a placement error names (by their path below the volume, e.g.
    // "adaptive.min_cell_size") with the message; "" clears the marks.
    void markProblem(const QString& message);
    // Wide enough for every row, hidden ones too: a dock sized for the shown rows would
    // squeeze the rows another placement shows.
    QSize minimumSizeHint() const override;

signals:
    void rejected(const QString& message);

protected:
    void showEvent(QShowEvent* e) override;

private:
    void addNumber(const ParameterSpec& spec);
    void addInteger(const ParameterSpec& spec);
    void addList(const ParameterSpec& spec);
    void addBool(const ParameterSpec& spec);
    void addChoice(const ParameterSpec& spec);
    void addColor(const ParameterSpec& spec);
    void addColorList(const ParameterSpec& spec);
    void addText(const ParameterSpec& spec);
    void addRow(const ParameterSpec& spec, QWidget* editor);
    // The document path a row edits (rows of a list's element: of the selected one).
    std::string docPath(const ParameterSpec& spec) const;
    // Whether the document reads the row now (rows of a list's element: for the selected one).
    bool isRead(const ParameterSpec& spec) const;
    void set(const std::string& path, const nlohmann::json& value);
    ProjectDocument* doc_;
    QFormLayout* form_;
    int element_ = 0;  // the probe volume or light the element rows edit
    std::vector<std::function<void()>> refreshers_;
    struct RowLabel {
        const ParameterSpec* spec;
        QLabel* label;
        QWidget* editor;
        QString tip;
    };
    std::vector<RowLabel> labels_;
};

// Probe Volumes: the list of volumes (add, remove, rename) and the selected volume's settings.
class ProbeVolumesPanel : public QWidget {
    Q_OBJECT
public:
    ProbeVolumesPanel(ProjectDocument* doc, QWidget* parent = nullptr);
    int currentVolume() const;
    void selectVolume(int index);
    // Per volume, why its placement fails ("" where it works): shown for the selected volume
    // above its settings, with the rows the message names marked.
    void setPlacementErrors(std::vector<QString> errors);

signals:
    void rejected(const QString& message);

private:
    void refresh();
    void showPlacementError();
    void editVolumes(const std::function<void(nlohmann::json&)>& edit, const QString& what);
    ProjectDocument* doc_;
    QListWidget* list_;
    ParameterForm* form_;
    QLabel* error_;
    std::vector<QString> errors_;
};

}  // namespace terralux
