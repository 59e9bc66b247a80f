#include "ParameterPanels.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <QApplication>
#include <QCheckBox>
#include <QColorDialog>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QInputDialog>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QPushButton>
#include <QRegularExpression>
#include <QSignalBlocker>
#include <QSlider>
#include <QSpinBox>
#include <QStyle>
#include <QVBoxLayout>
#include <QWheelEvent>

#include "ParameterTable.h"
#include "ProjectDocument.h"

namespace terralux {

using nlohmann::json;

namespace {

// The wheel scrolls the dock, not the value under the pointer: a field takes wheel steps only once
// it has focus (a click or Tab), so scrolling through a panel never edits what it passes over.
class WheelGuard : public QObject {
public:
    using QObject::QObject;
    bool eventFilter(QObject* watched, QEvent* e) override {
        if (e->type() != QEvent::Wheel) return false;
        auto* w = qobject_cast<QWidget*>(watched);
        if (!w || w->hasFocus()) return false;
        e->ignore();  // on to the parent: the dock's scroll area
        return true;
    }
};

void scrollsPastUnlessFocused(QWidget* w) {
    static WheelGuard* guard = new WheelGuard(qApp);
    w->setFocusPolicy(Qt::StrongFocus);
    w->installEventFilter(guard);
}

// A row shows the document's value only where it differs: setValue repaints the box even when
// the value stays, and every edit refreshes every shown row.
void showValue(QDoubleSpinBox* spin, double v) {
    if (spin->value() != QString::number(v, 'f', spin->decimals()).toDouble()) spin->setValue(v);
}

void showValue(QSpinBox* spin, int v) {
    if (spin->value() != v) spin->setValue(v);
}

}  // namespace

ParameterForm::ParameterForm(ProjectDocument* doc, QWidget* parent)
    : QWidget(parent), doc_(doc), form_(new QFormLayout(this)) {
    form_->setFieldGrowthPolicy(QFormLayout::AllNonFixedFieldsGrow);
    // A hidden form (a closed dock) catches up when shown (showEvent): its rows' resolved "auto"
    // values cost the UI thread milliseconds an edit need not spend. A dock behind another's
    // tab is not hidden (Qt moves it out of the window), so its form refreshes; its rows touch
    // only what changed.
    connect(doc_, &ProjectDocument::parametersChanged, this, [this] {
        if (isVisible()) refresh();
    });
}

void ParameterForm::setElement(int index) {
    element_ = index;
    refresh();
}

std::string ParameterForm::docPath(const ParameterSpec& spec) const {
    return spec.inList() ? spec.listPath() + "[" + std::to_string(element_) + "]." + spec.localPath() : spec.path;
}

void ParameterForm::set(const std::string& path, const json& value) {
    QString error;
    if (!doc_->setParameter(path, value, &error)) {
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

void ParameterForm::addWidget(QWidget* w) { form_->addRow(w); }

void ParameterForm::addParameters(const std::string& prefix) {
    for (const auto& spec : parameterTable())
        if (spec.uiRow && spec.path.rfind(prefix, 0) == 0) addParameter(spec.path);
}

void ParameterForm::addParameter(const std::string& path) {
    const ParameterSpec* spec = findParameter(path);
    if (!spec) throw std::logic_error("no parameter " + path);
    switch (spec->type) {
        case ParamType::Number: return addNumber(*spec);
        case ParamType::Integer: return addInteger(*spec);
        case ParamType::Boolean: return addBool(*spec);
        case ParamType::String: return addText(*spec);
        case ParamType::Choice: return addChoice(*spec);
        case ParamType::Color: return addColor(*spec);
        case ParamType::NumberList: return spec->colorList ? addColorList(*spec) : addList(*spec);
        case ParamType::IntegerList: return addList(*spec);
    }
}

void ParameterForm::addRow(const ParameterSpec& spec, QWidget* editor) {
    QString tip = QString::fromStdString(spec.description);
    if (!spec.consoleVariable.empty()) {
        // The name from lpv.ini's list heads the tip; the description's own copy of it goes.
        const QString cvar = QString::fromStdString(spec.consoleVariable);
        if (tip.startsWith(cvar + ": ")) tip = tip.mid(cvar.size() + 2);
        tip = "Console variable " + cvar + "\n" + tip;
    }
    if (spec.type != ParamType::Boolean && spec.type != ParamType::String)
        tip += QString::fromStdString("\nAllowed: " + (spec.type == ParamType::Choice ? spec.rangeText() : "each " + spec.rangeText()) +
                                      (spec.unit.empty() ? "" : " " + spec.unit));
    if (spec.autoMeaning) tip += QString::fromStdString("\nAuto: " + *spec.autoMeaning);
    tip += QString::fromStdString("\nProject path: " + spec.path);
    auto* label = new QLabel(QString::fromStdString(spec.label), this);
    label->setToolTip(tip);
    editor->setToolTip(tip);
    form_->addRow(label, editor);
    labels_.push_back({&spec, label, editor, tip});
    // A row the current settings do not read (grid_dims of an adaptive volume) is hidden, so
    // nothing on screen looks editable that changes nothing; its value is kept.
    refreshers_.push_back([=, this] { form_->setRowVisible(editor, isRead(spec)); });
}

QSize ParameterForm::minimumSizeHint() const {
    QSize size = QWidget::minimumSizeHint();
    int label = 0, field = 0;
    for (const RowLabel& r : labels_) {
        label = std::max(label, r.label->sizeHint().width());
        field = std::max(field, r.editor->minimumSizeHint().width());
    }
    const int spacing = form_->horizontalSpacing() >= 0 ? form_->horizontalSpacing()
                                                        : style()->pixelMetric(QStyle::PM_LayoutHorizontalSpacing);
    const QMargins m = form_->contentsMargins();
    size.setWidth(std::max(size.width(), m.left() + label + spacing + field + m.right()));
    return size;
}

void ParameterForm::markProblem(const QString& message) {
    for (const RowLabel& r : labels_) {
        // The row's own path as a whole word: "adaptive.max_cell_size", not "max_cell_size" inside it.
        const QRegularExpression named("(^|[^\\w.])" + QRegularExpression::escape(QString::fromStdString(r.spec->localPath())) + "\\b");
        const bool hit = !message.isEmpty() && named.match(message).hasMatch();
        r.label->setStyleSheet(hit ? "QLabel { color: #c62828; font-weight: bold }" : "");
        r.label->setToolTip(hit ? message + "\n\n" + r.tip : r.tip);
    }
}

bool ParameterForm::isRead(const ParameterSpec& spec) const {
    const SceneDescription& scene = doc_->project().scene;
    if (spec.perVolume() && size_t(element_) >= scene.probeVolumes.size()) return false;
    if (spec.perLight() && size_t(element_) >= scene.lights.size()) return false;
    if (spec.perScenario() && size_t(element_) >= scene.scenarios.size()) return false;
    return spec.isRead(scene, spec.inList() ? size_t(element_) : 0);
}

void ParameterForm::addNumber(const ParameterSpec& spec) {
    auto* row = new QWidget(this);
    auto* h = new QHBoxLayout(row);
    h->setContentsMargins(0, 0, 0, 0);
    auto* spin = new QDoubleSpinBox(row);
    scrollsPastUnlessFocused(spin);
    const QString name = QString::fromStdString(uiObjectName(spec));
    spin->setObjectName(name);
    const double step = std::pow(10.0, -spec.decimals);
    const double lo = uiMinimum(spec), hi = spec.max;
    const bool nullable = spec.nullable();
    // A nullable number shows its "auto" text one step below the smallest value.
    spin->setDecimals(spec.decimals);
    spin->setRange(nullable ? lo - step : lo, hi);
    if (nullable) spin->setSpecialValueText(QString::fromStdString(autoShort(spec)));
    spin->setSingleStep(std::pow(10.0, -std::min(spec.decimals, 2)) * (hi - lo > 100 ? 10 : 1));
    spin->setKeyboardTracking(false);
    if (!spec.unit.empty()) spin->setSuffix(QString::fromStdString(" " + spec.unit));
    QSlider* s = nullptr;
    if (spec.slider) {
        s = new QSlider(Qt::Horizontal, row);
        scrollsPastUnlessFocused(s);
        s->setObjectName(name + ".slider");
        s->setRange(0, 1000);
        h->addWidget(s, 1);
        connect(s, &QSlider::valueChanged, this, [=, this](int v) {
            set(docPath(spec), lo + (hi - lo) * v / 1000.0);
        });
    }
    h->addWidget(spin, s ? 0 : 1);
    connect(spin, &QDoubleSpinBox::valueChanged, this, [=, this](double v) {
        set(docPath(spec), nullable && v < lo ? json(nullptr) : json(v));
    });
    refreshers_.push_back([=, this] {
        const json v = doc_->value(docPath(spec));
        QSignalBlocker b1(spin);
        if (nullable) {
            // "auto" names what it resolves to on this terrain, where the table can say it.
            QString text = QString::fromStdString(autoShort(spec));
            if (v.is_null() && spec.resolved && isRead(spec)) {
                const json r = spec.resolved(doc_->project().scene, doc_->terrain().heightfield, size_t(element_));
                if (r.is_number())
                    text += QString(" (%1%2)")
                                .arg(QLocale().toString(r.get<double>(), 'f', spec.decimals))
                                .arg(spec.unit.empty() ? QString() : QString::fromStdString(" " + spec.unit));
            }
            if (spin->specialValueText() != text) spin->setSpecialValueText(text);
        }
        showValue(spin, v.is_number() ? v.get<double>() : lo - step);
        if (s && v.is_number()) {
            QSignalBlocker b2(s);
            s->setValue(int(std::lround((v.get<double>() - lo) / (hi - lo) * 1000.0)));
        }
    });
    addRow(spec, row);
}

void ParameterForm::addInteger(const ParameterSpec& spec) {
    auto* spin = new QSpinBox(this);
    scrollsPastUnlessFocused(spin);
    spin->setObjectName(QString::fromStdString(uiObjectName(spec)));
    const int lo = int(spec.min), hi = int(std::min<double>(spec.max, std::numeric_limits<int>::max()));
    const bool nullable = spec.nullable();
    spin->setRange(nullable ? lo - 1 : lo, hi);
    spin->setKeyboardTracking(false);
    if (nullable) spin->setSpecialValueText(QString::fromStdString(autoShort(spec)));
    else if (!spec.zeroText.empty() && lo == 0) spin->setSpecialValueText(QString::fromStdString(spec.zeroText));
    if (!spec.unit.empty()) spin->setSuffix(QString::fromStdString(" " + spec.unit));
    connect(spin, &QSpinBox::valueChanged, this, [=, this](int v) {
        set(docPath(spec), nullable && v < lo ? json(nullptr) : json(v));
    });
    refreshers_.push_back([=, this] {
        const json v = doc_->value(docPath(spec));
        QSignalBlocker b(spin);
        showValue(spin, v.is_number() ? v.get<int>() : lo - 1);
    });
    addRow(spec, spin);
}

void ParameterForm::addList(const ParameterSpec& spec) {
    auto* row = new QWidget(this);
    auto* h = new QHBoxLayout(row);
    h->setContentsMargins(0, 0, 0, 0);
    const QString name = QString::fromStdString(uiObjectName(spec));
    const bool integer = spec.type == ParamType::IntegerList;
    QCheckBox* autoBox = nullptr;
    if (spec.nullable()) {
        autoBox = new QCheckBox("auto", row);
        autoBox->setObjectName(name + ".auto");
        h->addWidget(autoBox);
    }
    std::vector<QAbstractSpinBox*> spins;
    for (int i = 0; i < spec.maxItems; ++i) {
        QAbstractSpinBox* spin;
        if (integer) {
            auto* sb = new QSpinBox(row);
            sb->setRange(int(spec.min), int(std::min<double>(spec.max, std::numeric_limits<int>::max())));
            spin = sb;
        } else {
            auto* sb = new QDoubleSpinBox(row);
            sb->setDecimals(spec.decimals);
            sb->setRange(uiMinimum(spec), spec.max);
            if (!spec.unit.empty()) sb->setSuffix(QString::fromStdString(" " + spec.unit));
            spin = sb;
        }
        spin->setObjectName(name + "." + QString::number(i));
        scrollsPastUnlessFocused(spin);
        spin->setKeyboardTracking(false);
        // Share the row's width: three wide spin boxes side by side would widen the dock.
        spin->setSizePolicy(QSizePolicy::Ignored, QSizePolicy::Fixed);
        // Wide enough for the values it holds, as a plain spin box would be (capped: a grid's
        // integer range would otherwise ask for the width of 2^31).
        spin->setMinimumWidth(std::clamp(spin->minimumSizeHint().width(), 56, 96));
        // Until the first refresh only the least a list holds is shown, so the dock's width
        // (taken when it is built) is not that of the longest list.
        spin->setVisible(i < std::max(spec.minItems, 1));
        h->addWidget(spin, 1);
        spins.push_back(spin);
    }
    auto number = [integer](QAbstractSpinBox* s) {
        return integer ? json(static_cast<QSpinBox*>(s)->value()) : json(static_cast<QDoubleSpinBox*>(s)->value());
    };
    // How many numbers the parameter holds in this scene: 0 means one plain number (box spacing).
    auto count = [=, this]() -> int {
        const json current = doc_->value(docPath(spec));
        if (current.is_array()) return int(current.size());
        if (current.is_number()) return 0;
        if (!isRead(spec)) return spec.maxItems;
        const int n = spec.items ? spec.items(doc_->project().scene, size_t(element_)) : spec.maxItems;
        return n < 0 ? spec.maxItems : n;
    };
    auto commit = [=, this] {
        if (autoBox && autoBox->isChecked()) return set(docPath(spec), nullptr);
        const int n = count();
        if (n == 0) return set(docPath(spec), number(spins[0]));
        json a = json::array();
        for (int i = 0; i < n && i < int(spins.size()); ++i) a.push_back(number(spins[size_t(i)]));
        set(docPath(spec), a);
    };
    for (auto* spin : spins) {
        if (integer) connect(static_cast<QSpinBox*>(spin), &QSpinBox::valueChanged, this, commit);
        else connect(static_cast<QDoubleSpinBox*>(spin), &QDoubleSpinBox::valueChanged, this, commit);
    }
    if (autoBox) connect(autoBox, &QCheckBox::toggled, this, commit);
    refreshers_.push_back([=, this] {
        const json v = doc_->value(docPath(spec));
        const int n = std::max(count(), 1);
        if (autoBox) {
            QSignalBlocker b(autoBox);
            autoBox->setChecked(v.is_null());
        }
        // While "auto" is ticked the greyed boxes show what it resolves to on this terrain (the
        // spacing the grid really has), not whatever they held.
        json shown = v;
        if (v.is_null() && spec.resolved && isRead(spec))
            shown = spec.resolved(doc_->project().scene, doc_->terrain().heightfield, size_t(element_));
        for (size_t i = 0; i < spins.size(); ++i) {
            QSignalBlocker b(spins[i]);
            spins[i]->setVisible(int(i) < n);
            spins[i]->setEnabled(!v.is_null());
            const json e = shown.is_array() && i < shown.size() ? shown[i]
                           : shown.is_number() && i == 0        ? shown
                                                                : json();
            if (!e.is_number()) continue;
            if (integer) showValue(static_cast<QSpinBox*>(spins[i]), e.get<int>());
            else showValue(static_cast<QDoubleSpinBox*>(spins[i]), e.get<double>());
        }
    });
    addRow(spec, row);
}

void ParameterForm::addBool(const ParameterSpec& spec) {
    auto* box = new QCheckBox(this);
    box->setObjectName(QString::fromStdString(uiObjectName(spec)));
    connect(box, &QCheckBox::toggled, this, [=, this](bool on) { set(docPath(spec), on); });
    refreshers_.push_back([=, this] {
        const json v = doc_->value(docPath(spec));
        QSignalBlocker b(box);
        box->setChecked(v.is_boolean() && v.get<bool>());
    });
    addRow(spec, box);
}

void ParameterForm::addChoice(const ParameterSpec& spec) {
    auto* combo = new QComboBox(this);
    scrollsPastUnlessFocused(combo);
    combo->setObjectName(QString::fromStdString(uiObjectName(spec)));
    for (const auto& c : spec.choices) combo->addItem(QString::fromStdString(c));
    connect(combo, &QComboBox::currentTextChanged, this,
            [=, this](const QString& t) { set(docPath(spec), t.toStdString()); });
    refreshers_.push_back([=, this] {
        const json v = doc_->value(docPath(spec));
        QSignalBlocker b(combo);
        if (v.is_string()) combo->setCurrentText(QString::fromStdString(v.get<std::string>()));
    });
    addRow(spec, combo);
}

namespace {

// Linear RGB in a colour button: the swatch (values above 1, sky radiance, clipped) and the numbers.
void showColor(QPushButton* button, double r, double g, double b) {
    const QColor c = QColor::fromRgbF(float(std::min(1.0, r)), float(std::min(1.0, g)), float(std::min(1.0, b)));
    const QString numbers = QString("%1, %2, %3").arg(r, 0, 'g', 3).arg(g, 0, 'g', 3).arg(b, 0, 'g', 3);
    const QString style = QString("QPushButton { background: %1; color: %2 }").arg(c.name(), c.lightnessF() > 0.5 ? "black" : "white");
    // Unchanged, the button is left alone: a style sheet set again re-polishes it, and every edit
    // refreshes the ramp's swatches (a third of an edit's milliseconds on the UI thread).
    if (button->text() == numbers && button->toolTip() == numbers && button->styleSheet() == style) return;
    button->setText(numbers);
    button->setToolTip(numbers);
    button->setStyleSheet(style);
}

// Asks for a colour starting from linear RGB; values above 1 (sky radiance) are kept as an
// intensity on top of the colour. False when the user cancels.
bool pickColor(QWidget* parent, const QString& title, double rgb[3]) {
    const double peak = std::max({rgb[0], rgb[1], rgb[2], 1.0});
    const QColor start = QColor::fromRgbF(float(rgb[0] / peak), float(rgb[1] / peak), float(rgb[2] / peak));
    const QColor c = QColorDialog::getColor(start, parent, title);
    if (!c.isValid()) return false;
    rgb[0] = c.redF() * peak;
    rgb[1] = c.greenF() * peak;
    rgb[2] = c.blueF() * peak;
    return true;
}

}  // namespace

void ParameterForm::addColor(const ParameterSpec& spec) {
    auto* button = new QPushButton(this);
    button->setObjectName(QString::fromStdString(uiObjectName(spec)));
    const QString title = QString::fromStdString(spec.label);
    connect(button, &QPushButton::clicked, this, [=, this] {
        json v = doc_->value(docPath(spec));
        // Left to the scene ("auto"): start from what it resolves to here, where the row can say.
        if (v.is_null() && spec.resolved)
            v = spec.resolved(doc_->project().scene, doc_->terrain().heightfield, size_t(element_));
        if (!v.is_array() || v.size() != 3) v = json{0.5, 0.5, 0.5};
        double rgb[3] = {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
        if (pickColor(this, title, rgb)) set(docPath(spec), json{rgb[0], rgb[1], rgb[2]});
    });
    refreshers_.push_back([=, this] {
        const json v = doc_->value(docPath(spec));
        if (v.is_null() && spec.autoMeaning) {
            // A colour the scene decides: say which, in the button's own colours.
            if (!button->styleSheet().isEmpty()) button->setStyleSheet(QString());
            button->setText(QString::fromStdString("auto: " + autoShort(spec)));
            return;
        }
        if (!v.is_array() || v.size() != 3) return;
        showColor(button, v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
    });
    addRow(spec, button);
}

// One colour button per RGB triple of the list (a ramp's stops), as many as the scene holds,
// three to a row, each as wide as its numbers (the dock widens to them).
void ParameterForm::addColorList(const ParameterSpec& spec) {
    auto* row = new QWidget(this);
    auto* h = new QGridLayout(row);
    h->setContentsMargins(0, 0, 0, 0);
    constexpr int kPerRow = 3;
    const QString name = QString::fromStdString(uiObjectName(spec));
    std::vector<QPushButton*> buttons;
    for (int stop = 0; stop < spec.maxItems / 3; ++stop) {
        auto* button = new QPushButton(row);
        button->setObjectName(name + "." + QString::number(stop));
        button->setSizePolicy(QSizePolicy::Preferred, QSizePolicy::Fixed);
        button->setVisible(stop < std::max(spec.minItems / 3, 1));
        h->addWidget(button, stop / kPerRow, stop % kPerRow);
        buttons.push_back(button);
        const QString title = QString::fromStdString(spec.label) + " " + QString::number(stop + 1);
        connect(button, &QPushButton::clicked, this, [=, this] {
            json v = doc_->value(docPath(spec));
            const size_t at = 3 * size_t(stop);
            if (!v.is_array() || v.size() < at + 3) return;
            double rgb[3] = {v[at].get<double>(), v[at + 1].get<double>(), v[at + 2].get<double>()};
            if (!pickColor(this, title, rgb)) return;
            for (size_t k = 0; k < 3; ++k) v[at + k] = rgb[k];
            set(docPath(spec), v);
        });
    }
    refreshers_.push_back([=, this] {
        const json v = doc_->value(docPath(spec));
        for (size_t stop = 0; stop < buttons.size(); ++stop) {
            const size_t at = 3 * stop;
            const bool shown = v.is_array() && v.size() >= at + 3;
            buttons[stop]->setVisible(shown);
            if (shown) showColor(buttons[stop], v[at].get<double>(), v[at + 1].get<double>(), v[at + 2].get<double>());
        }
    });
    addRow(spec, row);
}

void ParameterForm::addText(const ParameterSpec& spec) {
    auto* edit = new QLineEdit(this);
    edit->setObjectName(QString::fromStdString(uiObjectName(spec)));
    if (!spec.zeroText.empty()) edit->setPlaceholderText(QString::fromStdString(spec.zeroText));
    connect(edit, &QLineEdit::editingFinished, this, [=, this] { set(docPath(spec), edit->text().toStdString()); });
    refreshers_.push_back([=, this] {
        const json v = doc_->value(docPath(spec));
        QSignalBlocker b(edit);
        edit->setText(v.is_string() ? QString::fromStdString(v.get<std::string>()) : QString());
    });
    addRow(spec, edit);
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
    error_ = new QLabel(this);
    error_->setObjectName("volumes.placementError");
    error_->setWordWrap(true);
    error_->setStyleSheet("QLabel { color: #c62828; font-weight: bold }");
    error_->setVisible(false);
    v->addWidget(error_);
    form_ = new ParameterForm(doc_, this);
    form_->addParameters("probe_volumes[].");
    v->addWidget(form_);
    v->addStretch(1);
    connect(form_, &ParameterForm::rejected, this, &ProbeVolumesPanel::rejected);
    connect(list_, &QListWidget::currentRowChanged, this, [this](int row) {
        if (row >= 0) form_->setVolume(row);
        form_->setEnabled(row >= 0);
        showPlacementError();
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

void ProbeVolumesPanel::setPlacementErrors(std::vector<QString> errors) {
    errors_ = std::move(errors);
    showPlacementError();
}

void ProbeVolumesPanel::showPlacementError() {
    const int row = currentVolume();
    const QString message = row >= 0 && size_t(row) < errors_.size() ? errors_[size_t(row)] : QString();
    error_->setText(message);
    error_->setVisible(!message.isEmpty());
    form_->markProblem(message);
}

void ProbeVolumesPanel::editVolumes(const std::function<void(json&)>& edit, const QString&) {
    json volumes = doc_->value("probe_volumes");
    edit(volumes);
    QString error;
    if (!doc_->setParameter("probe_volumes", volumes, &error)) emit rejected(error);
}

void ProbeVolumesPanel::refresh() {
    const json volumes = doc_->value("probe_volumes");
    QStringList names;
    for (const auto& v : volumes) names << QString::fromStdString(v["name"].get<std::string>());
    // Every edit comes here: the list is rebuilt only when the names change, and the form (which
    // refreshed itself for the edit) is pointed at a volume only when the selection moved.
    bool same = list_->count() == names.size();
    for (int i = 0; same && i < names.size(); ++i) same = list_->item(i)->text() == names[i];
    const int keep = list_->currentRow();
    const int row = names.isEmpty() ? -1 : std::clamp(keep < 0 ? 0 : keep, 0, int(names.size()) - 1);
    {
        QSignalBlocker b(list_);
        if (!same) {
            list_->clear();
            list_->addItems(names);
        }
        if (!same || row != keep) list_->setCurrentRow(row);
    }
    if (row >= 0 && row != form_->element()) form_->setVolume(row);
    form_->setEnabled(row >= 0);
}

}  // namespace terralux
