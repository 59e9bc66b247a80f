#include "ScenarioPanel.h"

#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QPushButton>
#include <QSignalBlocker>
#include <QStackedWidget>
#include <QVBoxLayout>

#include "ParameterPanels.h"
#include "ParameterTable.h"
#include "Project.h"
#include "ProjectDocument.h"

namespace terralux {

using nlohmann::json;

ScenarioPanel::ScenarioPanel(ProjectDocument* doc, QWidget* defaults, QWidget* parent) : QWidget(parent), doc_(doc) {
    auto* outer = new QVBoxLayout(this);
    outer->setContentsMargins(0, 0, 0, 0);
    // The list and its buttons in the forms' margins; the forms below keep their own.
    auto* v = new QVBoxLayout;
    v->setContentsMargins(9, 6, 9, 0);
    outer->addLayout(v);
    auto* title = new QLabel("<b>Lighting scenarios</b>");
    title->setToolTip("Named suns and skies baked with the same probe layout (scenarios/<volume>.<scenario>.shprobe); "
                      "the one selected here is the one the viewport shows and these rows edit");
    v->addWidget(title);
    list_ = new QListWidget;
    list_->setObjectName("scenarios.list");
    list_->setMaximumHeight(4 * list_->fontMetrics().height() + 12);
    v->addWidget(list_);
    auto* buttons = new QHBoxLayout;
    add_ = new QPushButton("Add scenario");
    add_->setObjectName("scenarios.add");
    add_->setToolTip("A new scenario with the selected one's sun and sky, to change from there");
    remove_ = new QPushButton("Remove");
    remove_->setObjectName("scenarios.remove");
    name_ = new QLineEdit;
    name_->setObjectName("scenarios.name");
    name_->setPlaceholderText("name");
    name_->setToolTip(QString::fromStdString(findParameter("scenarios[].name")->patternRule));
    buttons->addWidget(add_);
    buttons->addWidget(remove_);
    buttons->addWidget(name_, 1);
    v->addLayout(buttons);
    error_ = new QLabel;
    error_->setObjectName("scenarios.error");
    error_->setWordWrap(true);
    error_->setStyleSheet("QLabel { color: #c62828 }");
    error_->hide();
    v->addWidget(error_);

    pages_ = new QStackedWidget;
    pages_->addWidget(defaults);
    form_ = new ParameterForm(doc_);
    form_->setObjectName("scenarios.editor");
    form_->addParameters("scenarios[].sun.");
    form_->addParameters("scenarios[].sky.");
    pages_->addWidget(form_);
    outer->addWidget(pages_);
    connect(form_, &ParameterForm::rejected, this, &ScenarioPanel::showRejection);

    connect(list_, &QListWidget::currentRowChanged, this, [this] {
        showSelected();
        emit currentScenarioChanged(currentScenario());
    });
    connect(add_, &QPushButton::clicked, this, [this] {
        const SceneDescription& scene = doc_->project().scene;
        const std::vector<std::string> names = scenarioNames(scene);
        std::string name;
        for (int k = int(names.size());; ++k) {
            name = "scenario-" + std::to_string(k);
            if (std::find(names.begin(), names.end(), name) == names.end()) break;
        }
        // The selected scenario's light, every key written as the table's rows read it.
        const SceneDescription from = scenarioScene(scene, currentScenario().toStdString());
        SceneDescription one;
        one.scenarios.push_back({name, from.sun, from.sky});
        json scenario = json::object();
        for (const ParameterSpec& spec : parameterTable())
            if (spec.perScenario()) {
                json* node = &scenario;
                const std::string local = spec.localPath();
                size_t start = 0;
                for (size_t dot; (dot = local.find('.', start)) != std::string::npos; start = dot + 1)
                    node = &(*node)[local.substr(start, dot - start)];
                (*node)[local.substr(start)] = spec.get(one, 0);
            }
        json scenarios = doc_->value("scenarios");
        if (!scenarios.is_array()) scenarios = json::array();
        scenarios.push_back(scenario);
        setScenarios(scenarios, QString("Add scenario '%1'").arg(QString::fromStdString(name)),
                     QString::fromStdString(name));
    });
    connect(remove_, &QPushButton::clicked, this, [this] {
        const int row = list_->currentRow() - 1;
        json scenarios = doc_->value("scenarios");
        if (!scenarios.is_array() || row < 0 || row >= int(scenarios.size())) return;
        const QString name = currentScenario();
        scenarios.erase(scenarios.begin() + row);
        setScenarios(scenarios, QString("Remove scenario '%1'").arg(name),
                     row < int(scenarios.size()) ? QString::fromStdString(scenarios[size_t(row)]["name"].get<std::string>())
                                                  : row > 0 ? QString::fromStdString(scenarios[size_t(row - 1)]["name"].get<std::string>())
                                                            : QString(kDefaultScenario));
    });
    connect(name_, &QLineEdit::editingFinished, this, [this] {
        const int row = list_->currentRow() - 1;
        const QString before = currentScenario(), after = name_->text().trimmed();
        if (row < 0 || after == before) return;
        QString error;
        if (!doc_->setParameters({{"scenarios[" + std::to_string(row) + "].name", after.toStdString()}}, &error,
                                 QString("Rename scenario '%1' to '%2'").arg(before, after))) {
            name_->setText(before);
            return showRejection(error);
        }
        selectScenario(after);
    });
    connect(doc_, &ProjectDocument::parametersChanged, this, [this](const QString& path) {
        error_->hide();
        if (path.isEmpty() || path.startsWith("scenarios")) refresh();
    });
    refresh();
}

QString ScenarioPanel::currentScenario() const {
    const QListWidgetItem* item = list_->currentItem();
    return item ? item->data(Qt::UserRole).toString() : QString(kDefaultScenario);
}

void ScenarioPanel::selectScenario(const QString& name) {
    for (int i = 0; i < list_->count(); ++i)
        if (list_->item(i)->data(Qt::UserRole).toString() == name) return list_->setCurrentRow(i);
    list_->setCurrentRow(0);
}

void ScenarioPanel::refresh() {
    const QString selected = currentScenario();
    {
        QSignalBlocker block(list_);
        list_->clear();
        for (const std::string& n : scenarioNames(doc_->project().scene)) {
            const QString name = QString::fromStdString(n);
            auto* item = new QListWidgetItem(n == kDefaultScenario ? "default (the project's sun and sky)" : name);
            item->setData(Qt::UserRole, name);
            list_->addItem(item);
        }
        int row = 0;
        for (int i = 0; i < list_->count(); ++i)
            if (list_->item(i)->data(Qt::UserRole).toString() == selected) row = i;
        list_->setCurrentRow(row);
    }
    showSelected();
    if (currentScenario() != selected) emit currentScenarioChanged(currentScenario());
}

void ScenarioPanel::showSelected() {
    const int row = list_->currentRow() - 1;
    const bool scenario = row >= 0;
    remove_->setEnabled(scenario);
    name_->setEnabled(scenario);
    name_->setText(scenario ? currentScenario() : QString());
    add_->setEnabled(int(doc_->project().scene.scenarios.size()) < kMaxScenarios);
    if (scenario) form_->setElement(row);
    form_->refresh();
    pages_->setCurrentIndex(scenario ? 1 : 0);
}

void ScenarioPanel::setScenarios(const json& scenarios, const QString& label, const QString& select) {
    QString error;
    if (!doc_->setParameters({{"scenarios", scenarios}}, &error, label)) return showRejection(error);
    selectScenario(select);
}

void ScenarioPanel::showRejection(const QString& message) {
    error_->setText(message);
    error_->show();
    emit rejected(message);
}

}  // namespace terralux
