// SPDX-License-Identifier: MIT
// Bounded queues between the stages of the runtime: a FIFO at the source whose policy
// (wait or drop the oldest) is the rig's, and an ordered queue that hands frames on in
// frame order whatever order parallel workers finish them in.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <optional>

namespace binocle {

// Frames waiting between the source and the first processing stage. `pushWait` blocks
// while the queue is full (lossless); `pushDropOldest` never blocks and gives back the
// frame it pushed out (latest). `pop` numbers what it hands out 0, 1, 2 ... so that
// later stages can restore that order.
template <typename T> class SourceQueue {
public:
    explicit SourceQueue(size_t capacity) : capacity_(capacity) {}

    // False when the queue was closed while waiting (the item is then left in `item`).
    bool pushWait(T &item) {
        std::unique_lock<std::mutex> lock(mutex_);
        notFull_.wait(lock, [&] { return closed_ || items_.size() < capacity_; });
        if (closed_) return false;
        items_.push_back(std::move(item));
        notEmpty_.notify_one();
        return true;
    }
    // Returns the oldest waiting item when it had to make room for this one.
    std::optional<T> pushDropOldest(T item) {
        std::optional<T> dropped;
        std::lock_guard<std::mutex> lock(mutex_);
        if (items_.size() >= capacity_) {
            dropped = std::move(items_.front());
            items_.pop_front();
        }
        items_.push_back(std::move(item));
        notEmpty_.notify_one();
        return dropped;
    }
    // Waits for an item; nullopt once the queue is closed and empty.
    std::optional<T> pop(uint64_t &ordinal) {
        std::unique_lock<std::mutex> lock(mutex_);
        notEmpty_.wait(lock, [&] { return closed_ || !items_.empty(); });
        if (items_.empty()) return std::nullopt;
        std::optional<T> item(std::move(items_.front()));
        items_.pop_front();
        ordinal = next_++;
        notFull_.notify_one();
        return item;
    }
    // No more pushes; pops drain what is left.
    void close() {
        std::lock_guard<std::mutex> lock(mutex_);
        closed_ = true;
        notEmpty_.notify_all();
        notFull_.notify_all();
    }

private:
    const size_t capacity_;
    std::mutex mutex_;
    std::condition_variable notEmpty_, notFull_;
    std::deque<T> items_;
    uint64_t next_ = 0;
    bool closed_ = false;
};

// Items numbered 0, 1, 2 ... come out in that order. A push waits while the queue holds
// `capacity` items, except for the item the consumer waits for (which never waits: the
// workers holding later items could otherwise block it for ever).
template <typename T> class OrderedQueue {
public:
    explicit OrderedQueue(size_t capacity) : capacity_(capacity) {}

    void push(uint64_t ordinal, T item) {
        std::unique_lock<std::mutex> lock(mutex_);
        notFull_.wait(lock, [&] { return items_.size() < capacity_ || ordinal == next_; });
        items_.emplace(ordinal, std::move(item));
        if (ordinal == next_) ready_.notify_all();
    }
    // The next item in order; nullopt once every producer is done and it is empty.
    std::optional<T> pop() {
        std::unique_lock<std::mutex> lock(mutex_);
        // Once the producers are gone nothing can fill a gap: hand on what is there.
        ready_.wait(lock, [&] { return producers_ == 0 || (!items_.empty() && items_.begin()->first == next_); });
        if (items_.empty()) return std::nullopt;
        next_ = items_.begin()->first + 1;
        std::optional<T> item(std::move(items_.begin()->second));
        items_.erase(items_.begin());
        notFull_.notify_all();
        return item;
    }
    void setProducers(int n) {
        std::lock_guard<std::mutex> lock(mutex_);
        producers_ = n;
    }
    // One producer is done; after the last, pop drains and then ends.
    void producerDone() {
        std::lock_guard<std::mutex> lock(mutex_);
        --producers_;
        ready_.notify_all();
    }

private:
    const size_t capacity_;
    std::mutex mutex_;
    std::condition_variable ready_, notFull_;
    std::map<uint64_t, T> items_;
    uint64_t next_ = 0;
    int producers_ = 1;
};

} // namespace binocle
