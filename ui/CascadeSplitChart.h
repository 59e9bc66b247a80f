#pragma once
// The Shadows dock's strip chart of the cascade splits: the view range the cascades cover (the
// project camera's, at the viewport's aspect, over the loaded terrain), each cascade a segment in
// its colour of the cascade view (34), the split distances labelled. In manual split mode the
// inner splits are handles to drag; a drag is one undoable edit of shadows.splits.

#include <optional>
#include <vector>

#include <QWidget>

#include "scene/ShadowCascades.h"

namespace terralux {

class ProjectDocument;

class CascadeSplitChart : public QWidget {
    Q_OBJECT
public:
    explicit CascadeSplitChart(ProjectDocument* doc, QWidget* parent = nullptr);

    // The range and ends drawn now (while dragging: with the dragged split).
    const CascadeRange& range() const { return range_; }
    // Where inner split `i` (0 .. cascades − 2) is drawn: the centre of its handle on the strip.
    QPoint handlePosition(int i) const;
    // The distance at x on the strip, and back.
    double distanceAt(double x) const;
    double xOf(double distance) const;

    QSize sizeHint() const override;
    QSize minimumSizeHint() const override;

signals:
    // An edit the document refused, with its message.
    void rejected(const QString& message);

public slots:
    // Reads the shadows section, the camera, the aspect and the terrain again.
    void refresh();

protected:
    void paintEvent(QPaintEvent* e) override;
    void mousePressEvent(QMouseEvent* e) override;
    void mouseMoveEvent(QMouseEvent* e) override;
    void mouseReleaseEvent(QMouseEvent* e) override;
    void changeEvent(QEvent* e) override;

private:
    bool manual() const;
    // The handle within reach of x, or -1.
    int handleAt(double x) const;
    QRect strip() const;
    ProjectDocument* doc_;
    CascadeRange range_;
    int dragging_ = -1;               // the inner split being dragged
    std::vector<double> dragSplits_;  // the splits as the drag has them
};

}  // namespace terralux
