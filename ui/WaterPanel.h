#pragma once
// The Water dock's own editors beyond the parameter rows: the wave list (add, remove, reorder,
// edit in place, presets) and the animation (Play/Pause and the time slider) that the viewport
// draws. Every edit of the waves is one undoable change of water.waves.

#include <QElapsedTimer>
#include <QTimer>
#include <QWidget>

class QComboBox;
class QLabel;
class QPushButton;
class QSlider;
class QTableWidget;

namespace terralux {

class ProjectDocument;
class ViewportWindow;

class WaterPanel : public QWidget {
    Q_OBJECT
public:
    WaterPanel(ProjectDocument* doc, ViewportWindow* viewport, QWidget* parent = nullptr);
    // Seconds the viewport's waves are at.
    double time() const;
    void setTime(double seconds);
    bool playing() const;

signals:
    void rejected(const QString& message);

private:
    void refresh();
    void commitTable(int editedRow, int editedColumn);
    void moveWave(int delta);
    ProjectDocument* doc_;
    ViewportWindow* viewport_;
    QTableWidget* table_;
    QPushButton *add_, *remove_, *up_, *down_, *play_;
    QComboBox* preset_;
    QSlider* slider_;
    QLabel* timeLabel_;
    QTimer clock_;
    QElapsedTimer wall_;  // since the last tick of Play
    bool refreshing_ = false;
};

}  // namespace terralux
