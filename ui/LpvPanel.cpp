#include "LpvPanel.h"

#include <algorithm>

#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QPushButton>
#include <QSignalBlocker>
#include <QTableWidget>
#include <QVBoxLayout>

#include "ParameterPanels.h"
#include "ParameterTable.h"
#include "ProjectDocument.h"
#include "scene/OrbitCamera.h"

namespace terralux {

namespace {

using nlohmann::json;

enum Column { kType, kPosition, kColour, kIntensity, kRange, kColumns };

QString numbers(const json& v) {
    QStringList parts;
    if (v.is_array())
        for (const json& e : v) parts << QString::number(e.get<double>(), 'g', 5);
    return parts.join(", ");
}

QTableWidgetItem* item(const QString& text) {
    auto* i = new QTableWidgetItem(text);
    i->setFlags(i->flags() & ~Qt::ItemIsEditable);  // edited in the light's fields below
    return i;
}

}  // namespace

LpvPanel::LpvPanel(ProjectDocument* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
    auto* v = new QVBoxLayout(this);
    v->setContentsMargins(0, 0, 0, 0);

    settings_ = new ParameterForm(doc_);
    settings_->addParameter("lighting.indirect");
    settings_->addParameters("lpv.");
    v->addWidget(settings_);

    auto* hintRow = new QHBoxLayout;
    hint_ = new QLabel;
    hint_->setObjectName("lpv.hint");
    hint_->setWordWrap(true);
    hintFix_ = new QPushButton;
    hintFix_->setObjectName("lpv.hintFix");
    hintRow->addWidget(hint_, 1);
    hintRow->addWidget(hintFix_);
    v->addLayout(hintRow);

    error_ = new QLabel;
    error_->setObjectName("lpv.error");
    error_->setWordWrap(true);
    error_->setStyleSheet("QLabel { color: #c62828 }");
    error_->hide();
    v->addWidget(error_);

    v->addWidget(new QLabel("Lights (point and spot; the LPV injects them with Local lights on)"));
    table_ = new QTableWidget(0, kColumns, this);
    table_->setObjectName("lights.table");
    table_->setHorizontalHeaderLabels({"Type", "Position (m)", "Colour", "Intensity (cd)", "Range (m)"});
    table_->horizontalHeader()->setSectionResizeMode(QHeaderView::Stretch);
    table_->verticalHeader()->setVisible(false);
    table_->setSelectionBehavior(QAbstractItemView::SelectRows);
    table_->setSelectionMode(QAbstractItemView::SingleSelection);
    table_->setMinimumHeight(110);
    table_->setToolTip("The project's lights; select one to edit it below");
    v->addWidget(table_);

    auto* buttons = new QHBoxLayout;
    add_ = new QPushButton("Add point");
    add_->setObjectName("lights.add");
    add_->setToolTip("A point light above the view's target (a copy of the selected light's colour, intensity and range)");
    addSpot_ = new QPushButton("Add spot");
    addSpot_->setObjectName("lights.addSpot");
    addSpot_->setToolTip("A spot light above the view's target, pointing down");
    delete_ = new QPushButton("Delete");
    delete_->setObjectName("lights.delete");
    for (auto* b : {add_, addSpot_, delete_}) buttons->addWidget(b);
    v->addLayout(buttons);

    light_ = new ParameterForm(doc_);
    light_->setObjectName("lights.editor");
    light_->addParameters("lights[].");
    v->addWidget(light_);

    for (ParameterForm* f : {settings_, light_})
        connect(f, &ParameterForm::rejected, this, &LpvPanel::showRejection);
    connect(add_, &QPushButton::clicked, this, [this] { addLight(false); });
    connect(addSpot_, &QPushButton::clicked, this, [this] { addLight(true); });
    connect(delete_, &QPushButton::clicked, this, [this] {
        json lights = doc_->value("lights");
        const int row = currentLight();
        if (!lights.is_array() || row < 0 || row >= int(lights.size())) return;
        lights.erase(lights.begin() + row);
        setLights(lights, std::min(row, int(lights.size()) - 1));
    });
    connect(table_, &QTableWidget::currentCellChanged, this, [this](int row) {
        light_->setElement(std::max(row, 0));
        delete_->setEnabled(row >= 0);
    });
    connect(hintFix_, &QPushButton::clicked, this, [this] {
        const SceneDescription& scene = doc_->project().scene;
        QString error;
        const bool ok = scene.lpv.enabled
                            ? doc_->setParameter("lighting.indirect",
                                                 scene.lighting.indirect == IndirectLighting::None ? "lpv" : "both", &error)
                            : doc_->setParameter("lpv.enabled", true, &error);
        if (!ok) showRejection(error);
    });
    connect(doc_, &ProjectDocument::parametersChanged, this, [this](const QString& path) {
        // A change that went through clears the last refusal.
        error_->hide();
        if (path.isEmpty() || path.startsWith("lights")) refresh();
        if (path.isEmpty() || path.startsWith("lpv") || path.startsWith("lighting")) refreshHint();
    });
    refresh();
    refreshHint();
}

void LpvPanel::refreshHint() {
    const SceneDescription& scene = doc_->project().scene;
    const bool on = scene.lpv.enabled;
    const IndirectLighting mode = scene.lighting.indirect;
    const bool lit = mode == IndirectLighting::Lpv || mode == IndirectLighting::Both;
    const std::string indirect = doc_->value("lighting.indirect").get<std::string>();
    if (on == lit) {
        hint_->hide();
        hintFix_->hide();
        return;
    }
    if (on) {
        hint_->setText(QString("The LPV is computed but adds no light: Indirect light is '%1'. Only its debug "
                               "views (61 to 64) show it.")
                           .arg(QString::fromStdString(indirect)));
        hintFix_->setText(indirect == "none" ? "Light with the LPV" : "Light with probes and LPV");
        hintFix_->setToolTip(QString("Sets Indirect light to '%1': one undoable edit")
                                 .arg(indirect == "none" ? "lpv" : "both"));
    } else {
        hint_->setText(QString("Indirect light is '%1', but Light propagation volumes is off: the views get "
                               "no LPV light and the bake exports none.")
                           .arg(QString::fromStdString(indirect)));
        hintFix_->setText("Turn the LPV on");
        hintFix_->setToolTip("Ticks Light propagation volumes: one undoable edit");
    }
    hint_->show();
    hintFix_->show();
}

int LpvPanel::currentLight() const { return table_->currentRow(); }

void LpvPanel::selectLight(int index) { table_->selectRow(index); }

void LpvPanel::showRejection(const QString& message) {
    error_->setText(message);
    error_->show();
    emit rejected(message);
}

void LpvPanel::setLights(const json& lights, int select) {
    QString error;
    if (!doc_->setParameter("lights", lights, &error)) return showRejection(error);
    if (select >= 0) table_->selectRow(select);
}

void LpvPanel::addLight(bool spot) {
    json lights = doc_->value("lights");
    if (!lights.is_array()) lights = json::array();
    // Where the user looks, a little above it, so the new light is in view and over the ground.
    const OrbitCamera camera = OrbitCamera::fromSettings(doc_->project().scene.camera, doc_->terrain().heightfield);
    const SceneDescription& scene = doc_->project().scene;
    LocalLight l;
    const int row = currentLight();
    if (row >= 0 && row < int(scene.lights.size())) {
        const LocalLight& selected = scene.lights[size_t(row)];
        l.color = selected.color;
        l.intensity = selected.intensity;
        l.range = selected.range;
    }
    l.type = spot ? LocalLightType::Spot : LocalLightType::Point;
    l.position = camera.target + glm::vec3(0.0f, 20.0f, 0.0f);
    l.direction = glm::vec3(0.0f, -1.0f, 0.0f);
    // Every key written, as the table's rows read it: the dock's fields show the document's JSON.
    SceneDescription one;
    one.lights.push_back(l);
    json light = json::object();
    for (const ParameterSpec& spec : parameterTable())
        if (spec.perLight()) light[spec.localPath()] = spec.get(one, 0);
    lights.push_back(light);
    setLights(lights, int(lights.size()) - 1);
}

void LpvPanel::refresh() {
    // The project's values with defaults filled in (a light in the file may leave keys out).
    const SceneDescription& scene = doc_->project().scene;
    const int n = int(scene.lights.size());
    const int selected = table_->currentRow();
    {
        const QSignalBlocker block(table_);
        table_->setRowCount(n);
        for (int i = 0; i < n; ++i) {
            const LocalLight& l = scene.lights.at(size_t(i));
            table_->setItem(i, kType, item(l.type == LocalLightType::Spot ? "spot" : "point"));
            table_->setItem(i, kPosition, item(numbers(json{l.position.x, l.position.y, l.position.z})));
            table_->setItem(i, kColour, item(numbers(json{l.color.x, l.color.y, l.color.z})));
            table_->setItem(i, kIntensity, item(QString::number(l.intensity, 'g', 6)));
            table_->setItem(i, kRange, item(QString::number(l.range, 'g', 6)));
        }
    }
    const int keep = selected >= 0 && selected < n ? selected : n > 0 ? 0 : -1;
    if (keep >= 0) table_->selectRow(keep);
    light_->setElement(std::max(keep, 0));
    light_->setVisible(n > 0);
    delete_->setEnabled(keep >= 0);
    add_->setEnabled(n < kMaxLocalLights);
    addSpot_->setEnabled(n < kMaxLocalLights);
}

}  // namespace terralux
