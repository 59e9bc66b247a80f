#pragma once
// When the viewport updates the light propagation volumes: lpv.update_interval counts the
// viewport's frames (docs/lighting.md, "Light propagation volumes", "In the viewport"). Between
// two updates at least `interval` frames pass without one (0: any frame may update), and an
// update starts only when the frame wants volumes other than those last started (a settings or
// camera change) and no update is under way; a change waits for the next frame its turn allows.

#include <cstdint>
#include <string>

namespace terralux::lpv {

class UpdateSchedule {
public:
    explicit UpdateSchedule(int interval = 0) : interval_(interval < 0 ? 0 : interval) {}
    void setInterval(int frames) { interval_ = frames < 0 ? 0 : frames; }
    int interval() const { return interval_; }

    // One frame that wants the volumes `key` while an update is (`busy`) or is not under way.
    // True: this frame starts the update for `key`.
    bool frame(const std::string& key, bool busy) {
        ++frame_;
        if (started_ && key == key_) {
            pending_ = false;
            return false;
        }
        pending_ = true;
        if (busy) return false;
        if (started_ && frame_ - lastStart_ <= interval_) return false;
        started_ = true;
        key_ = key;
        lastStart_ = frame_;
        pending_ = false;
        ++updates_;
        return true;
    }
    // A frame wanted other volumes than the last update's and did not start it: more frames are
    // needed for the change to land.
    bool pending() const { return pending_; }
    // Whether the last update started was for `key`.
    bool startedFor(const std::string& key) const { return started_ && key == key_; }
    // Forgets the last update (the volumes it made were dropped): the next frame starts one.
    void reset() {
        started_ = false;
        pending_ = false;
        key_.clear();
    }
    uint64_t frames() const { return frame_; }
    uint64_t updates() const { return updates_; }

private:
    int interval_ = 0;
    int64_t frame_ = 0, lastStart_ = 0;
    bool started_ = false, pending_ = false;
    std::string key_;
    uint64_t updates_ = 0;
};

}  // namespace terralux::lpv
