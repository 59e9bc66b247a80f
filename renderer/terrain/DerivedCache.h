#pragma once
// Values derived from a heightfield (and settings named by a key), kept under the grid's serial
// (Heightfield::serial) so that an edit of the project that changes neither does not compute them
// again: the water's auto level, a placement a dock shows "auto" as. The last few are kept;
// thread-safe (a value may be computed twice by two threads at once, never kept wrong).

#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

namespace terralux {

template <class Value>
class DerivedCache {
public:
    explicit DerivedCache(size_t capacity = 4) : capacity_(capacity) {}

    // The value for (serial, key), from `compute()` when not kept. Serial 0 (the empty grid) is
    // never kept.
    template <class Compute>
    std::shared_ptr<const Value> get(uint64_t serial, const std::string& key, Compute&& compute) {
        if (serial != 0) {
            std::lock_guard lock(mutex_);
            for (const Entry& e : entries_)
                if (e.serial == serial && e.key == key) return e.value;
        }
        auto value = std::make_shared<const Value>(compute());
        if (serial != 0) {
            std::lock_guard lock(mutex_);
            entries_.push_front(Entry{serial, key, value});
            if (entries_.size() > capacity_) entries_.pop_back();
        }
        return value;
    }

private:
    struct Entry {
        uint64_t serial;
        std::string key;
        std::shared_ptr<const Value> value;
    };
    size_t capacity_;
    std::mutex mutex_;
    std::deque<Entry> entries_;
};

}  // namespace terralux
