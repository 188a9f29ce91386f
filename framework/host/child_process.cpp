// SPDX-License-Identifier: MIT
// A child process with a deadline (fork, a pipe for its answer, SIGKILL at the deadline).
#include "host/child_process.hpp"

#include "core/error.hpp"

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

namespace binocle {

std::string describeSignal(int sig) {
    const char *abbrev = sigabbrev_np(sig);
    return "signal " + std::to_string(sig) + (abbrev ? std::string(" (SIG") + abbrev + ")" : std::string());
}

std::string describeExit(int status) {
    if (WIFSIGNALED(status)) return "killed by " + describeSignal(WTERMSIG(status));
    if (WIFEXITED(status)) return "exited with status " + std::to_string(WEXITSTATUS(status));
    return "ended (status " + std::to_string(status) + ")";
}

int killAndReap(pid_t pid) {
    ::kill(pid, SIGKILL);
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return status;
}

DeadlineChild::DeadlineChild(const std::function<std::string()> &body, int32_t timeout_ms) {
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) throw Error(std::string("pipe: ") + std::strerror(errno));
    std::fflush(nullptr); // nothing buffered may be written twice by a child
    start_ = Clock::now();
    deadline_ = start_ + std::chrono::milliseconds(timeout_ms);
    pid_ = ::fork();
    if (pid_ == 0) {
        ::close(fds[0]);
        const std::string out = body();
        const char *p = out.data();
        size_t left = out.size();
        while (left > 0) {
            const ssize_t n = ::write(fds[1], p, left);
            if (n <= 0) break;
            p += n;
            left -= static_cast<size_t>(n);
        }
        ::_exit(0);
    }
    ::close(fds[1]);
    if (pid_ < 0) {
        ::close(fds[0]);
        throw Error(std::string("fork: ") + std::strerror(errno));
    }
    pipe_ = fds[0];
}

DeadlineChild::~DeadlineChild() {
    if (pid_ > 0) killAndReap(pid_);
    if (pipe_ >= 0) ::close(pipe_);
}

int DeadlineChild::remainingMs() const {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline_ - Clock::now()).count();
    return left > 0 ? static_cast<int>(left) : 0;
}

bool DeadlineChild::readSome() {
    if (closed_) return true;
    char buf[4096];
    const ssize_t n = ::read(pipe_, buf, sizeof buf);
    if (n > 0) output_.append(buf, static_cast<size_t>(n));
    else if (n == 0 || errno != EINTR) closed_ = true; // end of file: the child ended
    return closed_;
}

DeadlineChild::End DeadlineChild::finish() {
    End end;
    if (pid_ > 0) {
        if (closed_) {
            while (::waitpid(pid_, &end.status, 0) < 0 && errno == EINTR) {
            }
        } else {
            end.status = killAndReap(pid_);
            end.timedOut = true;
        }
        pid_ = -1;
    }
    end.output = output_;
    end.seconds = std::chrono::duration<double>(Clock::now() - start_).count();
    return end;
}

DeadlineChild::End DeadlineChild::run(const std::function<std::string()> &body, int32_t timeout_ms) {
    DeadlineChild child(body, timeout_ms);
    for (;;) {
        const int left = child.remainingMs();
        if (left <= 0) break;
        pollfd p{child.fd(), POLLIN, 0};
        if (::poll(&p, 1, left) <= 0) continue;
        if (child.readSome()) break;
    }
    return child.finish();
}

} // namespace binocle
