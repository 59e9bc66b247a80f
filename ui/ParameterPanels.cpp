#include "ParameterPanels.h"

#include <cmath>
#include <limits>

#include <QCheckBox>
#include <QColorDialog>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QInputDialog>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QPushButton>
#include <QSignalBlocker>
#include <QSlider>
#include <QSpinBox>
#include <QVBoxLayout>

#include "ProjectDocument.h"

namespace terralux {

using nlohmann::json;

ParameterForm::ParameterForm(ProjectDocument* doc, QWidget* parent)
    : QWidget(parent), doc_(doc), form_(new QFormLayout(this)) {
    form_->setFieldGrowthPolicy(QFormLayout::AllNonFixedFieldsGrow);
    connect(doc_, &ProjectDocument::parametersChanged, this, [this] { refresh(); });
}

QString ParameterForm::objectNameFor(const std::string& path) const {
    return QString::fromStdString("param." + namePrefix_ + path);
}

void ParameterForm::set(const std::string& path, const json& value) {
    QString error;
    if (!doc_->setParameter(full(path), value, &error)) {
        emit rejected(error);
        refresh();  // back to the valid value
    }
}

void ParameterForm::refresh() {
    for (auto& r : refreshers_) r();
}

void ParameterForm::showEvent(QShowEvent* e) {
    refresh();  // rows added after the document loaded show its values
    QWidget::showEvent(e);
}

void ParameterForm::addWidget(const QString& label, QWidget* w) { form_->addRow(label, w); }

void ParameterForm::addNumber(const std::string& path, const QString& label, double min, double max,
                              int decimals, const QString& unit, bool slider) {
    auto* row = new QWidget(this);
    auto* h = new QHBoxLayout(row);
    h->setContentsMargins(0, 0, 0, 0);
    auto* spin = new QDoubleSpinBox(row);
    spin->setObjectName(objectNameFor(path));
    spin->setRange(min, max);
    spin->setDecimals(decimals);
    spin->setSingleStep(std::pow(10.0, -std::min(decimals, 2)) * (max - min > 100 ? 10 : 1));
    spin->setKeyboardTracking(false);
    if (!unit.isEmpty()) spin->setSuffix(" " + unit);
    QSlider* s = nullptr;
    if (slider) {
        s = new QSlider(Qt::Horizontal, row);
        s->setObjectName(objectNameFor(path) + ".slider");
        s->setRange(0, 1000);
        h->addWidget(s, 1);
        connect(s, &QSlider::valueChanged, this, [=, this](int v) {
            set(path, min + (max - min) * v / 1000.0);
        });
    }
    h->addWidget(spin, slider ? 0 : 1);
    connect(spin, &QDoubleSpinBox::valueChanged, this, [=, this](double v) { set(path, v); });
    refreshers_.push_back([=, this] {
        const json v = doc_->value(full(path));
        if (!v.is_number()) return;
        QSignalBlocker b1(spin);
        spin->setValue(v.get<double>());
        if (s) {
            QSignalBlocker b2(s);
            s->setValue(int(std::lround((v.get<double>() - min) / (max - min) * 1000.0)));
        }
    });
    form_->addRow(label, row);
}

void ParameterForm::addInteger(const std::string& path, const QString& label, int min, int max,
                               const QString& nullText) {
    auto* spin = new QSpinBox(this);
    spin->setObjectName(objectNameFor(path));
    spin->setRange(nullText.isEmpty() ? min : min - 1, max);
    spin->setKeyboardTracking(false);
    if (!nullText.isEmpty()) spin->setSpecialValueText(nullText);
    connect(spin, &QSpinBox::valueChanged, this, [=, this](int v) {
        set(path, (!nullText.isEmpty() && v == min - 1) ? json(nullptr) : json(v));
    });
    refreshers_.push_back([=, this] {
        const json v = doc_->value(full(path));
        QSignalBlocker b(spin);
        spin->setValue(v.is_number() ? v.get<int>() : min - 1);
    });
    form_->addRow(label, spin);
}

void ParameterForm::addOptionalNumber(const std::string& path, const QString& label, double max,
                                      int decimals, const QString& unit, const QString& nullText) {
    auto* spin = new QDoubleSpinBox(this);
    spin->setObjectName(objectNameFor(path));
    spin->setRange(-1.0, max);
    spin->setDecimals(decimals);
    spin->setSpecialValueText(nullText);
    spin->setKeyboardTracking(false);
    if (!unit.isEmpty()) spin->setSuffix(" " + unit);
    connect(spin, &QDoubleSpinBox::valueChanged, this, [=, this](double v) {
        set(path, v < 0.0 ? json(nullptr) : json(v));
    });
    refreshers_.push_back([=, this] {
        const json v = doc_->value(full(path));
        QSignalBlocker b(spin);
        spin->setValue(v.is_number() ? v.get<double>() : -1.0);
    });
    form_->addRow(label, spin);
}

void ParameterForm::addIntegerArray(const std::string& path, const QString& label, int count,
                                    int min, int max) {
    auto* row = new QWidget(this);
    auto* h = new QHBoxLayout(row);
    h->setContentsMargins(0, 0, 0, 0);
    std::vector<QSpinBox*> spins;
    for (int i = 0; i < count; ++i) {
        auto* spin = new QSpinBox(row);
        spin->setObjectName(objectNameFor(path) + "." + QString::number(i));
        spin->setRange(min, max);
        spin->setKeyboardTracking(false);
        h->addWidget(spin);
        spins.push_back(spin);
    }
    for (auto* spin : spins)
        connect(spin, &QSpinBox::valueChanged, this, [=, this] {
            // As many values as the parameter holds now (2 for terrain grids, 3 for boxes).
            const json current = doc_->value(full(path));
            const size_t n = current.is_array() ? std::min(current.size(), spins.size()) : spins.size();
            json a = json::array();
            for (size_t i = 0; i < n; ++i) a.push_back(spins[i]->value());
            set(path, a);
        });
    refreshers_.push_back([=, this] {
        const json v = doc_->value(full(path));
        for (size_t i = 0; i < spins.size(); ++i) {
            QSignalBlocker b(spins[i]);
            spins[i]->setVisible(v.is_array() && i < v.size());
            if (v.is_array() && i < v.size()) spins[i]->setValue(v[i].get<int>());
        }
    });
    form_->addRow(label, row);
}

void ParameterForm::addBool(const std::string& path, const QString& label) {
    auto* box = new QCheckBox(this);
    box->setObjectName(objectNameFor(path));
    connect(box, &QCheckBox::toggled, this, [=, this](bool on) { set(path, on); });
    refreshers_.push_back([=, this] {
        const json v = doc_->value(full(path));
        QSignalBlocker b(box);
        box->setChecked(v.is_boolean() && v.get<bool>());
    });
    form_->addRow(label, box);
}

void ParameterForm::addChoice(const std::string& path, const QString& label, const QStringList& choices) {
    auto* combo = new QComboBox(this);
    combo->setObjectName(objectNameFor(path));
    combo->addItems(choices);
    connect(combo, &QComboBox::currentTextChanged, this,
            [=, this](const QString& t) { set(path, t.toStdString()); });
    refreshers_.push_back([=, this] {
        const json v = doc_->value(full(path));
        QSignalBlocker b(combo);
        if (v.is_string()) combo->setCurrentText(QString::fromStdString(v.get<std::string>()));
    });
    form_->addRow(label, combo);
}

void ParameterForm::addColor(const std::string& path, const QString& label) {
    auto* button = new QPushButton(this);
    button->setObjectName(objectNameFor(path));
    connect(button, &QPushButton::clicked, this, [=, this] {
        const json v = doc_->value(full(path));
        // Linear values above 1 (sky radiance) are kept as an intensity on top of the colour.
        const double peak = std::max({v[0].get<double>(), v[1].get<double>(), v[2].get<double>(), 1.0});
        const QColor start = QColor::fromRgbF(float(v[0].get<double>() / peak), float(v[1].get<double>() / peak),
                                              float(v[2].get<double>() / peak));
        const QColor c = QColorDialog::getColor(start, this, label);
        if (c.isValid()) set(path, json{c.redF() * peak, c.greenF() * peak, c.blueF() * peak});
    });
    refreshers_.push_back([=, this] {
        const json v = doc_->value(full(path));
        if (!v.is_array() || v.size() != 3) return;
        const QColor c = QColor::fromRgbF(float(std::min(1.0, v[0].get<double>())),
                                          float(std::min(1.0, v[1].get<double>())),
                                          float(std::min(1.0, v[2].get<double>())));
        button->setText(QString("%1, %2, %3").arg(v[0].get<double>(), 0, 'g', 3)
                            .arg(v[1].get<double>(), 0, 'g', 3).arg(v[2].get<double>(), 0, 'g', 3));
        button->setStyleSheet(QString("QPushButton { background: %1; color: %2 }")
                                  .arg(c.name(), c.lightnessF() > 0.5 ? "black" : "white"));
    });
    form_->addRow(label, button);
}

void ParameterForm::addText(const std::string& path, const QString& label) {
    auto* edit = new QLineEdit(this);
    edit->setObjectName(objectNameFor(path));
    connect(edit, &QLineEdit::editingFinished, this, [=, this] { set(path, edit->text().toStdString()); });
    refreshers_.push_back([=, this] {
        const json v = doc_->value(full(path));
        QSignalBlocker b(edit);
        edit->setText(v.is_string() ? QString::fromStdString(v.get<std::string>()) : QString());
    });
    form_->addRow(label, edit);
}

ProbeVolumesPanel::ProbeVolumesPanel(ProjectDocument* doc, QWidget* parent)
    : QWidget(parent), doc_(doc) {
    auto* v = new QVBoxLayout(this);
    list_ = new QListWidget(this);
    list_->setObjectName("volumes.list");
    list_->setMaximumHeight(110);
    v->addWidget(list_);
    auto* buttons = new QHBoxLayout;
    auto* add = new QPushButton("Add", this);
    add->setObjectName("volumes.add");
    auto* remove = new QPushButton("Remove", this);
    remove->setObjectName("volumes.remove");
    auto* rename = new QPushButton("Rename…", this);
    rename->setObjectName("volumes.rename");
    buttons->addWidget(add);
    buttons->addWidget(remove);
    buttons->addWidget(rename);
    v->addLayout(buttons);
    form_ = new ParameterForm(doc_, this);
    form_->setNamePrefix("volume.");
    form_->addBool("enabled", "Enabled");
    form_->addChoice("placement", "Placement", {"terrain", "box", "adaptive"});
    form_->addIntegerArray("grid_dims", "Grid (probes)", 3, 1, 4096);
    form_->addNumber("height_offset", "Height offset", -1000.0, 10000.0, 2, "m");
    form_->addInteger("ray_count", "Rays per probe", 1, 1 << 20, "preset");
    form_->addOptionalNumber("fallback_blend_distance", "Fallback blend", 1e7, 1, "m", "2 × spacing");
    // Adaptive placement (seed 001's octree): cell sizes, the surface band, error-driven
    // refinement and its budgets.
    form_->addOptionalNumber("adaptive.min_cell_size", "Adaptive: min cell", 1e6, 2, "m", "DEM cell");
    form_->addOptionalNumber("adaptive.max_cell_size", "Adaptive: max cell", 1e7, 2, "m", "16 × min");
    form_->addNumber("adaptive.height_range", "Adaptive: above terrain", 0.0, 1e5, 1, "m");
    form_->addOptionalNumber("adaptive.surface_band", "Adaptive: surface band", 1e6, 2, "m", "1 min cell");
    form_->addOptionalNumber("adaptive.tolerance", "Adaptive: error tolerance", 1.0, 3, "", "geometric only");
    form_->addInteger("adaptive.max_probes", "Adaptive: max probes", 1, std::numeric_limits<int>::max(), "no limit");
    form_->addNumber("adaptive.max_move_share", "Adaptive: max move", 0.0, 0.5, 2, "of a cell");
    v->addWidget(form_);
    v->addStretch(1);
    connect(form_, &ParameterForm::rejected, this, &ProbeVolumesPanel::rejected);
    connect(list_, &QListWidget::currentRowChanged, this, [this](int row) {
        if (row >= 0) form_->setPrefix("probe_volumes[" + std::to_string(row) + "].");
        form_->setEnabled(row >= 0);
    });
    connect(add, &QPushButton::clicked, this, [this] {
        editVolumes([](json& volumes) {
            json v = defaultProjectJson()["probe_volumes"][0];
            int n = int(volumes.size()) + 1;
            auto taken = [&](const std::string& name) {
                for (const auto& e : volumes)
                    if (e.value("name", std::string()) == name) return true;
                return false;
            };
            while (taken("volume" + std::to_string(n))) ++n;
            v["name"] = "volume" + std::to_string(n);
            volumes.push_back(v);
        }, "add");
        selectVolume(list_->count() - 1);
    });
    connect(remove, &QPushButton::clicked, this, [this] {
        const int row = currentVolume();
        if (row < 0) return;
        editVolumes([row](json& volumes) { volumes.erase(volumes.begin() + row); }, "remove");
    });
    connect(rename, &QPushButton::clicked, this, [this] {
        const int row = currentVolume();
        if (row < 0) return;
        bool ok = false;
        const QString name = QInputDialog::getText(this, "Rename volume", "Name (file stem of its .shprobe):",
                                                   QLineEdit::Normal, list_->item(row)->text(), &ok);
        if (ok) editVolumes([&](json& volumes) { volumes[size_t(row)]["name"] = name.toStdString(); }, "rename");
    });
    connect(doc_, &ProjectDocument::parametersChanged, this, [this] { refresh(); });
    refresh();
}

int ProbeVolumesPanel::currentVolume() const { return list_->currentRow(); }
void ProbeVolumesPanel::selectVolume(int index) { list_->setCurrentRow(index); }

void ProbeVolumesPanel::editVolumes(const std::function<void(json&)>& edit, const QString&) {
    json volumes = doc_->value("probe_volumes");
    edit(volumes);
    QString error;
    if (!doc_->setParameter("probe_volumes", volumes, &error)) emit rejected(error);
}

void ProbeVolumesPanel::refresh() {
    const json volumes = doc_->value("probe_volumes");
    const int keep = list_->currentRow();
    QSignalBlocker b(list_);
    list_->clear();
    for (const auto& v : volumes) list_->addItem(QString::fromStdString(v["name"].get<std::string>()));
    const int row = volumes.empty() ? -1 : std::clamp(keep < 0 ? 0 : keep, 0, int(volumes.size()) - 1);
    list_->setCurrentRow(row);
    if (row >= 0) form_->setPrefix("probe_volumes[" + std::to_string(row) + "].");
    form_->setEnabled(row >= 0);
}

}  // namespace terralux
