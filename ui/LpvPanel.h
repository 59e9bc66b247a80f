#pragma once
// The LPV dock: the light propagation volume settings (each row one engine console variable),
// what indirect light the viewport adds, and the local lights: a table of the lights (Add point,
// Add spot, Delete) and the selected light's editors. Every edit is one undoable document change.
// When the LPV and the indirect light disagree (the LPV on but not lighting the views, or asked
// for but off), a note under the settings says so and offers the edit that makes them agree.

#include <QWidget>

#include <nlohmann/json.hpp>

class QLabel;
class QPushButton;
class QTableWidget;

namespace terralux {

class ParameterForm;
class ProjectDocument;

class LpvPanel : public QWidget {
    Q_OBJECT
public:
    explicit LpvPanel(ProjectDocument* doc, QWidget* parent = nullptr);
    int currentLight() const;
    void selectLight(int index);

signals:
    void rejected(const QString& message);

private:
    void refresh();
    // Says when the LPV is on but lights nothing (lighting.indirect leaves it out), or the
    // indirect light asks for an LPV that is off, with the one edit that makes them agree.
    void refreshHint();
    void addLight(bool spot);
    void showRejection(const QString& message);
    // Replaces the whole list: one undo step for an added or deleted light.
    void setLights(const nlohmann::json& lights, int select);
    ProjectDocument* doc_;
    ParameterForm* settings_;
    QTableWidget* table_;
    QPushButton *add_, *addSpot_, *delete_;
    ParameterForm* light_;
    QLabel* error_;
    QLabel* hint_;
    QPushButton* hintFix_;
};

}  // namespace terralux
