// SPDX-License-Identifier: MIT
// The transport of `isolation: process`: one message per request on a SOCK_SEQPACKET
// socket, in chunks when large, shared memory files (memfd) passed with SCM_RIGHTS.
// Pixels and arrays cross in those files (ipc_planes.hpp), never through the socket.
// Internal to host/.
#pragma once

#include <string>

namespace binocle::wire {

// Sends one message (in chunks when it is large), with a file descriptor attached when
// fd >= 0. False when the peer is gone (no SIGPIPE). Callers on several threads of one
// process serialise their sends.
bool sendMessage(int sock, const std::string &msg, int fd = -1);
// Receives one message; *fd is -1 when none came along (fd may be NULL). False at end of
// stream or on a malformed message.
bool receiveMessage(int sock, std::string &msg, int *fd);

} // namespace binocle::wire
