#pragma once
// The lighting scenarios of the Sun & Sky dock: a list of the scenarios ("default" first, the
// project's own sun and sky), Add (a copy of the selected scenario's sun and sky under a new
// name), Remove and Rename, and the selected scenario's sun and sky. The default's are the dock's
// own rows (`defaults`); another scenario's are the scenarios[] rows of the parameter table. Every
// change is one undoable document edit. The scenario selected here is the one the viewport shows.

#include <QWidget>

#include <nlohmann/json.hpp>

class QLabel;
class QLineEdit;
class QListWidget;
class QPushButton;
class QStackedWidget;

namespace terralux {

class ParameterForm;
class ProjectDocument;

class ScenarioPanel : public QWidget {
    Q_OBJECT
public:
    ScenarioPanel(ProjectDocument* doc, QWidget* defaults, QWidget* parent = nullptr);
    // The selected scenario's name ("default" for the project's own lighting).
    QString currentScenario() const;
    void selectScenario(const QString& name);

signals:
    void currentScenarioChanged(const QString& name);
    void rejected(const QString& message);

private:
    void refresh();
    void showSelected();
    // Replaces the whole list: one undo step named `label`, then selects `select`.
    void setScenarios(const nlohmann::json& scenarios, const QString& label, const QString& select);
    void showRejection(const QString& message);
    ProjectDocument* doc_;
    QListWidget* list_;
    QPushButton *add_, *remove_;
    QLineEdit* name_;
    QStackedWidget* pages_;
    ParameterForm* form_;
    QLabel* error_;
};

}  // namespace terralux
