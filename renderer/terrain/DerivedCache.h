#pragma once
// Values derived from a heightfield (and settings named by a key), kept under the grid's serial
// (Heightfield::serial) so that an edit of the project that changes neither does not compute them
// again: the water's auto level, a placement a dock shows "auto" as. The last few are kept, and
// with a byte budget no more than it holds (the newest is always kept); thread-safe (a value may
// be computed twice by two threads at once, never kept wrong).

#include <cstdint>
#include <deque>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

namespace terralux {

template <class Value>
class DerivedCache {
public:
    explicit DerivedCache(size_t capacity = 4) : capacity_(capacity) {}
    // At most `maxBytes` kept, as `bytesOf` counts a value.
    DerivedCache(size_t capacity, size_t maxBytes, std::function<size_t(const Value&)> bytesOf)
        : capacity_(capacity), maxBytes_(maxBytes), bytesOf_(std::move(bytesOf)) {}

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
            const size_t bytes = bytesOf_ ? bytesOf_(*value) : 0;
            std::lock_guard lock(mutex_);
            entries_.push_front(Entry{serial, key, value, bytes});
            keptBytes_ += bytes;
            while (entries_.size() > capacity_ || (entries_.size() > 1 && keptBytes_ > maxBytes_)) {
                keptBytes_ -= entries_.back().bytes;
                entries_.pop_back();
            }
        }
        return value;
    }
    // What is kept: how many values, and their bytes as counted.
    size_t size() const {
        std::lock_guard lock(mutex_);
        return entries_.size();
    }
    size_t bytes() const {
        std::lock_guard lock(mutex_);
        return keptBytes_;
    }

private:
    struct Entry {
        uint64_t serial;
        std::string key;
        std::shared_ptr<const Value> value;
        size_t bytes;
    };
    size_t capacity_;
    size_t maxBytes_ = std::numeric_limits<size_t>::max();
    std::function<size_t(const Value&)> bytesOf_;
    size_t keptBytes_ = 0;
    mutable std::mutex mutex_;
    std::deque<Entry> entries_;
};

}  // namespace terralux
