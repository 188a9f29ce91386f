// SPDX-License-Identifier: MIT
// The caller's spelling of its arguments; the stop flag of a job.
#include "app/request.hpp"

#include <binocle/text.hpp>

#include <algorithm>

namespace binocle::app {

std::string Caller::arg(const std::string &name) const {
    if (python()) return name;
    std::string option = "--" + name;
    std::replace(option.begin(), option.end(), '_', '-');
    return option;
}

std::string Caller::shown(const std::string &name, const std::string &value) const {
    const std::string text = sdk::printable(value);
    return python() ? name + "='" + text + "'" : arg(name) + " " + text;
}

OutputClaim Caller::claim(OutputKind kind, bool force) const {
    return OutputClaim{kind, force, command, python() ? "force=True" : arg("force")};
}

StopFlag::StopFlag(const std::atomic<bool> *stop) : stop_(stop) {
    if (stop_) return;
    signals_.emplace();
    stop_ = &StopSignalGuard::requested();
}

} // namespace binocle::app
