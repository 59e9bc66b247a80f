#pragma once
// The window's background work (its jobs' threads, the renderer's workers and the TBB worker
// threads their parallel loops draw in) runs below the UI thread's priority. On a machine with
// few cores that work otherwise keeps the UI thread waiting for a processor after each of its
// sleeps: 35-45 ms at a time on 2 cores while a 16 384² DEM landed.

#include <memory>

namespace terralux {

// The nice value background threads take: while both want a processor the scheduler gives a
// thread at nice 10 about a tenth of the share of one at 0, and all of it when the other sleeps.
inline constexpr int kBackgroundNice = 10;

// The calling thread's nice value (Linux threads carry their own; 0 elsewhere).
int threadNice();

// Held by a thread that does background work: lowers its priority to kBackgroundNice, and that of
// every TBB worker thread that joins its parallel loops while it is held. Linux only (elsewhere
// it does nothing). The priorities stay lowered (raising them again needs privileges): hold one
// only on a thread that does background work for the rest of its life, and where TBB's workers
// serve background work alone (the window: the UI thread runs no parallel loop of its own that
// must keep pace with it).
class BackgroundThread {
public:
    BackgroundThread();
    ~BackgroundThread();
    BackgroundThread(const BackgroundThread&) = delete;
    BackgroundThread& operator=(const BackgroundThread&) = delete;

private:
    struct Observer;
    std::unique_ptr<Observer> observer_;
};

}  // namespace terralux
