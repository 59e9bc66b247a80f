#include "WaterPanel.h"

#include <cmath>

#include <QComboBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QPushButton>
#include <QSlider>
#include <QTableWidget>
#include <QVBoxLayout>

#include "ProjectDocument.h"
#include "ViewportWindow.h"
#include "water/Water.h"

namespace terralux {

namespace {

using nlohmann::json;

// Columns of the wave table; amplitude and steepness are two faces of one number (A = S / k):
// the one a wave sets is plain, the one derived from it grey.
enum Column { kDirection, kWavelength, kAmplitude, kSteepness, kPhase, kColumns };

// The time slider's span and step: ten minutes in tenths of a second, then it wraps.
constexpr int kSliderSteps = 6000;
constexpr double kSliderStep = 0.1;

QTableWidgetItem* numberItem(double v, bool derived) {
    auto* item = new QTableWidgetItem(QString::number(v, 'g', 4));
    if (derived) item->setForeground(QColor(128, 128, 128));
    return item;
}

}  // namespace

WaterPanel::WaterPanel(ProjectDocument* doc, ViewportWindow* viewport, QWidget* parent)
    : QWidget(parent), doc_(doc), viewport_(viewport) {
    auto* v = new QVBoxLayout(this);
    v->setContentsMargins(0, 0, 0, 0);
    v->addWidget(new QLabel("Waves (Gerstner; the crests' summed steepness Σ k·A is at most 1)"));
    table_ = new QTableWidget(0, kColumns, this);
    table_->setObjectName("water.waves");
    table_->setHorizontalHeaderLabels({"Direction (°)", "Wavelength (m)", "Amplitude (m)", "Steepness k·A", "Phase (rad)"});
    table_->horizontalHeader()->setSectionResizeMode(QHeaderView::Stretch);
    table_->verticalHeader()->setVisible(false);
    table_->setSelectionBehavior(QAbstractItemView::SelectRows);
    table_->setSelectionMode(QAbstractItemView::SingleSelection);
    table_->setMinimumHeight(140);
    table_->setToolTip("Direction: the way the wave travels, clockwise from north. Edit the amplitude or the "
                       "steepness; the other follows from the wavelength.");
    v->addWidget(table_);

    auto* buttons = new QHBoxLayout;
    add_ = new QPushButton("Add");
    add_->setObjectName("water.addWave");
    remove_ = new QPushButton("Remove");
    remove_->setObjectName("water.removeWave");
    up_ = new QPushButton("Up");
    up_->setObjectName("water.waveUp");
    down_ = new QPushButton("Down");
    down_->setObjectName("water.waveDown");
    for (auto* b : {add_, remove_, up_, down_}) buttons->addWidget(b);
    v->addLayout(buttons);

    preset_ = new QComboBox;
    preset_->setObjectName("water.preset");
    preset_->addItem("Wave preset…");
    for (const std::string& name : water::wavePresetNames()) preset_->addItem(QString::fromStdString(name));
    preset_->setToolTip("Replaces the wave list with a preset (undoable)");
    v->addWidget(preset_);

    auto* animation = new QHBoxLayout;
    play_ = new QPushButton("Play");
    play_->setObjectName("water.play");
    play_->setCheckable(true);
    play_->setToolTip("Animates the waves in the viewport; paused, the viewport draws only when something changes");
    slider_ = new QSlider(Qt::Horizontal);
    slider_->setObjectName("water.time");
    slider_->setRange(0, kSliderSteps);
    slider_->setToolTip("Seconds into the wave animation (terralux --render --time)");
    timeLabel_ = new QLabel("0.0 s");
    timeLabel_->setObjectName("water.timeLabel");
    timeLabel_->setMinimumWidth(56);
    animation->addWidget(play_);
    animation->addWidget(slider_, 1);
    animation->addWidget(timeLabel_);
    v->addLayout(animation);

    connect(add_, &QPushButton::clicked, this, [this] {
        json waves = doc_->value("water.waves");
        if (!waves.is_array()) waves = json::array();
        const int row = table_->currentRow();
        // A copy of the selected wave turned a little, or a gentle swell.
        json wave = row >= 0 && row < int(waves.size())
                        ? waves[size_t(row)]
                        : json{{"direction_deg", 0.0}, {"wavelength", 20.0}, {"amplitude", 0.1}, {"phase", 0.0}};
        if (row >= 0) wave["direction_deg"] = std::fmod(wave.value("direction_deg", 0.0) + 30.0, 360.0);
        waves.push_back(wave);
        QString error;
        if (!doc_->setParameter("water.waves", waves, &error)) emit rejected(error);
        table_->selectRow(int(waves.size()) - 1);
    });
    connect(remove_, &QPushButton::clicked, this, [this] {
        json waves = doc_->value("water.waves");
        const int row = table_->currentRow();
        if (!waves.is_array() || row < 0 || row >= int(waves.size())) return;
        waves.erase(waves.begin() + row);
        QString error;
        if (!doc_->setParameter("water.waves", waves, &error)) emit rejected(error);
    });
    connect(up_, &QPushButton::clicked, this, [this] { moveWave(-1); });
    connect(down_, &QPushButton::clicked, this, [this] { moveWave(1); });
    connect(preset_, &QComboBox::activated, this, [this](int index) {
        if (index <= 0) return;
        json waves = json::array();
        for (const GerstnerWave& w : water::wavePreset(preset_->itemText(index).toStdString())) {
            json j{{"direction_deg", w.directionDeg}, {"wavelength", w.wavelength}, {"phase", w.phase}};
            if (w.amplitude) j["amplitude"] = *w.amplitude;
            if (w.steepness) j["steepness"] = *w.steepness;
            waves.push_back(j);
        }
        QString error;
        if (!doc_->setParameter("water.waves", waves, &error)) emit rejected(error);
        preset_->setCurrentIndex(0);
    });
    connect(table_, &QTableWidget::cellChanged, this, [this](int row, int column) {
        if (!refreshing_) commitTable(row, column);
    });

    // Play advances the time by the wall clock between ticks; paused, nothing ticks.
    clock_.setInterval(33);
    connect(play_, &QPushButton::toggled, this, [this](bool on) {
        play_->setText(on ? "Pause" : "Play");
        if (on) {
            wall_.start();
            clock_.start();
        } else {
            clock_.stop();
        }
    });
    connect(&clock_, &QTimer::timeout, this, [this] {
        const double dt = double(wall_.restart()) / 1000.0;
        double t = time() + dt;
        if (t > kSliderSteps * kSliderStep) t = std::fmod(t, kSliderSteps * kSliderStep);
        setTime(t);
    });
    connect(slider_, &QSlider::valueChanged, this, [this](int value) {
        // The slider holds tenths; Play's time runs finer and is kept unless the user moved it.
        if (std::lround(time() / kSliderStep) != value) setTime(value * kSliderStep);
    });
    connect(doc_, &ProjectDocument::parametersChanged, this, [this](const QString& path) {
        if (path.isEmpty() || path.startsWith("water")) refresh();
    });
    refresh();
}

double WaterPanel::time() const { return viewport_ ? viewport_->waterTime() : slider_->value() * kSliderStep; }

bool WaterPanel::playing() const { return play_->isChecked(); }

void WaterPanel::setTime(double seconds) {
    if (viewport_) viewport_->setWaterTime(seconds);
    const QSignalBlocker block(slider_);
    slider_->setValue(int(std::lround(seconds / kSliderStep)));
    timeLabel_->setText(QString::number(seconds, 'f', 1) + " s");
}

void WaterPanel::refresh() {
    refreshing_ = true;
    const json waves = doc_->value("water.waves");
    const int n = waves.is_array() ? int(waves.size()) : 0;
    const int selected = table_->currentRow();
    table_->setRowCount(n);
    for (int i = 0; i < n; ++i) {
        const json& w = waves[size_t(i)];
        GerstnerWave g;
        g.wavelength = w.value("wavelength", 1.0);
        const bool bySteepness = w.contains("steepness");
        if (bySteepness) g.steepness = w["steepness"].get<double>();
        else g.amplitude = w.value("amplitude", 0.0);
        const water::WaveTerms t = water::waveTerms(g);
        table_->setItem(i, kDirection, numberItem(w.value("direction_deg", 0.0), false));
        table_->setItem(i, kWavelength, numberItem(g.wavelength, false));
        table_->setItem(i, kAmplitude, numberItem(t.amplitude, bySteepness));
        table_->setItem(i, kSteepness, numberItem(t.k * t.amplitude, !bySteepness));
        table_->setItem(i, kPhase, numberItem(w.value("phase", 0.0), false));
    }
    if (selected >= 0 && selected < n) table_->selectRow(selected);
    add_->setEnabled(n < WaterSettings::kMaxWaves);
    remove_->setEnabled(n > 0);
    up_->setEnabled(n > 1);
    down_->setEnabled(n > 1);
    refreshing_ = false;
}

void WaterPanel::commitTable(int editedRow, int editedColumn) {
    const json current = doc_->value("water.waves");
    json waves = json::array();
    for (int i = 0; i < table_->rowCount(); ++i) {
        auto number = [&](int column) {
            const QTableWidgetItem* item = table_->item(i, column);
            bool ok = false;
            const double v = item ? item->text().toDouble(&ok) : 0.0;
            return ok ? json(v) : json(item ? item->text().toStdString() : "");
        };
        json w{{"direction_deg", number(kDirection)}, {"wavelength", number(kWavelength)}, {"phase", number(kPhase)}};
        // The edited face of the height wins; elsewhere the face the wave already had.
        const bool hadSteepness = current.is_array() && i < int(current.size()) && current[size_t(i)].contains("steepness");
        const bool bySteepness = i == editedRow ? editedColumn == kSteepness || (editedColumn != kAmplitude && hadSteepness)
                                                : hadSteepness;
        if (bySteepness) w["steepness"] = number(kSteepness);
        else w["amplitude"] = number(kAmplitude);
        waves.push_back(w);
    }
    QString error;
    if (!doc_->setParameter("water.waves", waves, &error)) {
        emit rejected(error);
        refresh();  // back to what the project holds
    }
}

void WaterPanel::moveWave(int delta) {
    json waves = doc_->value("water.waves");
    const int row = table_->currentRow(), to = row + delta;
    if (!waves.is_array() || row < 0 || to < 0 || row >= int(waves.size()) || to >= int(waves.size())) return;
    std::swap(waves[size_t(row)], waves[size_t(to)]);
    QString error;
    if (!doc_->setParameter("water.waves", waves, &error)) emit rejected(error);
    table_->selectRow(to);
}

}  // namespace terralux
