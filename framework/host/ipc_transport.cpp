// SPDX-License-Identifier: MIT
// The transport of `isolation: process`: messages in chunks on a SOCK_SEQPACKET
// socket, with a file descriptor attached.
#include "host/ipc_transport.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <sys/socket.h>
#include <unistd.h>

namespace binocle::wire {

namespace {

// A SOCK_SEQPACKET message must fit the socket's buffer (about 200 kB by default):
// larger ones (a rig's YAML, a long statistics text) go in chunks, each led by a byte
// that says whether more follow.
constexpr size_t kChunk = 64 * 1024;
constexpr size_t kMaxMessage = 256u << 20;

bool sendChunk(int sock, const char *data, size_t size, bool more, int fd) {
    uint8_t flag = more ? 1 : 0;
    iovec iov[2] = {{&flag, 1}, {const_cast<char *>(data), size}};
    msghdr h{};
    h.msg_iov = iov;
    h.msg_iovlen = 2;
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int))] = {};
    if (fd >= 0) {
        h.msg_control = control;
        h.msg_controllen = sizeof control;
        cmsghdr *c = CMSG_FIRSTHDR(&h);
        c->cmsg_level = SOL_SOCKET;
        c->cmsg_type = SCM_RIGHTS;
        c->cmsg_len = CMSG_LEN(sizeof(int));
        std::memcpy(CMSG_DATA(c), &fd, sizeof fd);
    }
    ssize_t n;
    do {
        n = ::sendmsg(sock, &h, MSG_NOSIGNAL);
    } while (n < 0 && errno == EINTR);
    return n == static_cast<ssize_t>(size + 1);
}

} // namespace

bool sendMessage(int sock, const std::string &msg, int fd) {
    size_t at = 0;
    do {
        const size_t n = std::min(kChunk, msg.size() - at);
        const bool more = at + n < msg.size();
        if (!sendChunk(sock, msg.data() + at, n, more, at == 0 ? fd : -1)) return false;
        at += n;
    } while (at < msg.size());
    return true;
}

bool receiveMessage(int sock, std::string &msg, int *fd) {
    msg.clear();
    if (fd) *fd = -1;
    std::string chunk(kChunk + 1, '\0');
    for (;;) {
        iovec iov{chunk.data(), chunk.size()};
        msghdr h{};
        h.msg_iov = &iov;
        h.msg_iovlen = 1;
        alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int))] = {};
        h.msg_control = control;
        h.msg_controllen = sizeof control;
        ssize_t n;
        do {
            n = ::recvmsg(sock, &h, MSG_CMSG_CLOEXEC);
        } while (n < 0 && errno == EINTR);
        if (n <= 0) return false;
        for (cmsghdr *c = CMSG_FIRSTHDR(&h); c; c = CMSG_NXTHDR(&h, c))
            if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_RIGHTS) {
                int received = -1;
                std::memcpy(&received, CMSG_DATA(c), sizeof(int));
                if (fd && *fd < 0) *fd = received;
                else ::close(received);
            }
        msg.append(chunk.data() + 1, static_cast<size_t>(n) - 1);
        if (chunk[0] == 0) return true;
        if (msg.size() > kMaxMessage) return false;
    }
}

} // namespace binocle::wire
