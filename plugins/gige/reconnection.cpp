// SPDX-License-Identifier: MIT
// Losing and reopening cameras off the grab thread.
#include "reconnection.hpp"

#include <sstream>

namespace binocle::gige {

namespace {

std::string formatMs(double ms) {
    std::ostringstream s;
    s.precision(ms < 10 ? 2 : 0);
    s << std::fixed << ms;
    return s.str();
}

double msBetween(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); }

std::string afterFrame(const Slot &slot) {
    return slot.lastSequence < 0 ? "before the first frame" : "after frame " + std::to_string(slot.lastSequence);
}

} // namespace

Reconnection::Reconnection(const ReconnectionSettings &settings, Slots &slots, Pairing &pairing, std::shared_ptr<Notifier> notifier,
                           sdk::Host &host, const std::atomic<bool> &running)
    : settings_(settings), slots_(slots), pairing_(pairing), notifier_(std::move(notifier)), host_(host), running_(running) {}

void Reconnection::shutdown() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        if (closing_) return;
        closing_ = true;
    }
    wake_.notify_all();
    for (auto &slot : slots_) slot->trigger.reset();
    for (auto &t : background_) t.join(); // closes lost cameras (may wait for Aravis timeouts)
}

std::string Reconnection::retrying() const {
    return settings_.reconnect ? "; reconnecting every " + std::to_string(settings_.retryInterval.count()) + " ms" : "; reconnect is off";
}

bool Reconnection::anyDisconnected() const {
    for (const auto &slot : slots_)
        if (!slot->camera) return true;
    return false;
}

std::string Reconnection::detectLoss(Clock::time_point now) {
    std::string message;
    for (auto &slotPtr : slots_) {
        Slot &slot = *slotPtr;
        if (!slot.camera) continue;
        std::string why = slot.camera->lostReason();
        if (why.empty() && slot.awaitingSince && now - *slot.awaitingSince > settings_.lostAfter)
            why = "no image for " + formatMs(msBetween(*slot.awaitingSince, now)) + " ms";
        if (why.empty()) continue;
        slot.lostWhy = why;
        slot.camera->markLost(why); // from now on nothing talks to it
        ++slot.losses;
        slot.retired += slot.camera->counters();
        const std::string label = slot.camera->label();
        loseCamera(slot);
        message += (message.empty() ? "gige: " : "; ") + std::string("camera ") + label + " stopped answering " + afterFrame(slot) +
                   " (" + why + ")";
    }
    if (message.empty()) return message;
    for (auto &slot : slots_) {
        pairing_.dropPending(*slot, true);
        // No trigger goes out while a camera is away: the others owe no image.
        if (settings_.trigger == Trigger::Software) slot->awaitingSince.reset();
    }
    pairing_.forgetTrigger();
    return message + retrying();
}

void Reconnection::loseCamera(Slot &slot) {
    pairing_.dropPending(slot, false);
    std::shared_ptr<Camera> dead = std::move(slot.camera);
    slot.awaitingSince.reset();
    Slot *s = &slot;
    std::lock_guard<std::mutex> lock(mutex_);
    s->attempts = 0;
    s->lastAttemptError.clear();
    // Closing a camera that is gone waits for control-channel timeouts (its trigger
    // thread too, when a trigger is in flight): never in grab.
    background_.emplace_back([dead = std::move(dead), trigger = std::move(s->trigger)]() mutable {
        trigger.reset();
        dead.reset();
    });
    if (settings_.reconnect) background_.emplace_back([this, s] { reconnectLoop(*s); });
}

void Reconnection::reconnectLoop(Slot &slot) {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!closing_) {
        wake_.wait_for(lock, settings_.retryInterval, [&] { return closing_; });
        if (closing_) return;
        ++slot.attempts;
        const CameraSettings settings = slot.settings;
        lock.unlock();
        std::shared_ptr<Camera> camera;
        std::string error;
        try {
            camera = std::make_shared<Camera>(settings, notifier_, false);
            if (camera->width() != settings_.width || camera->height() != settings_.height)
                throw sdk::Error(BINOCLE_ERR_DEVICE, "gige: camera " + camera->label() + " is back with " + sizeText(*camera) +
                                                         " images instead of " + std::to_string(settings_.width) + "x" +
                                                         std::to_string(settings_.height));
            if (running_) camera->start();
        } catch (const std::exception &e) {
            error = e.what();
            camera.reset();
        }
        lock.lock();
        if (camera) {
            slot.reconnected = std::move(camera);
            lock.unlock();
            notifier_->notify();
            return;
        }
        slot.lastAttemptError = error;
    }
}

void Reconnection::adoptReconnected() {
    bool any = false;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        for (auto &slot : slots_) {
            if (!slot->reconnected) continue;
            slot->camera = std::move(slot->reconnected);
            slot->lastFrameId.reset(); // a reopened camera numbers its frames anew
            if (settings_.trigger == Trigger::Software) slot->trigger = std::make_unique<TriggerWorker>(slot->camera);
            host_.info("gige: camera " + slot->camera->label() + " is back (" + std::to_string(slot->attempts) +
                       " attempt(s)); streaming again");
            ++reconnections_;
            any = true;
        }
    }
    if (!any) return;
    const Clock::time_point now = Clock::now();
    for (auto &slot : slots_) {
        pairing_.dropPending(*slot, true);
        if (!slot->camera) continue;
        if (running_ && !slot->camera->acquiring()) slot->camera->start(); // start() raced the reopening
        if (!running_) slot->camera->stop();
        if (running_ && settings_.trigger == Trigger::FreeRun) slot->awaitingSince = now;
    }
    pairing_.forgetTrigger();
}

std::string Reconnection::disconnectedMessage() {
    std::string message;
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto &slot : slots_) {
        if (slot->camera) continue;
        message += (message.empty() ? "gige: " : "; ") + std::string("camera ") + slot->settings.id + " (" + slot->settings.role +
                   ") is disconnected since " +
                   (slot->lastSequence < 0 ? std::string("the start") : "frame " + std::to_string(slot->lastSequence)) + " (" +
                   slot->lostWhy + ")";
        if (settings_.reconnect)
            message += "; reconnecting every " + std::to_string(settings_.retryInterval.count()) + " ms, " +
                       std::to_string(slot->attempts) + " attempt(s)" +
                       (slot->lastAttemptError.empty() ? "" : ", last: " + slot->lastAttemptError);
        else
            message += "; reconnect is off";
    }
    return message;
}

} // namespace binocle::gige
