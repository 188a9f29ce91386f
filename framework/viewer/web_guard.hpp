// SPDX-License-Identifier: MIT
// The viewer's request checks, free of any socket: which Host and Origin are served,
// which binds need the user's word, safe download names, and a log that an attacker
// cannot flood.
#pragma once

#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

namespace binocle::viewer {

// Whether `address` (an IP literal) is a loopback address (127.0.0.0/8, ::1, and
// IPv4-mapped 127.x). False for anything else, names included.
bool isLoopbackAddress(const std::string &address);

// The Host rule, against DNS rebinding. A request is served when its Host header
// ("name[:port]") names
//  - the address the connection arrived on, as an IP literal (a browser on another machine
//    opening http://192.168.1.10:8080/ when the server listens there or on 0.0.0.0), or
//    any loopback literal when it arrived on loopback;
//  - "localhost", when the connection arrived on loopback;
//  - a name the user allowed (--allow-host), case-insensitively.
// A client on the network sending "Host: 127.0.0.1" is refused: its connection did not
// arrive on loopback. `localAddress` is the connection's local endpoint address.
bool hostAllowed(std::string_view host, const std::string &localAddress, const std::vector<std::string> &allowedNames);

// Same origin: `origin` ("http://name[:port]") names exactly the host and port of the
// Host header (default port 80 on either side), so a page served by another local
// server on another port is not this page. "null" and other schemes are refused.
bool sameOrigin(std::string_view origin, std::string_view host);

// Why binding `address` needs the user's word (--allow-remote), or "" for loopback (and
// for a text that is no IP address, which the server refuses when it binds). The
// page's token then travels in clear over the network, and the Host rule admits the
// machine's addresses.
std::string remoteBindRisk(const std::string &address);
// The refusal of a bind that needs --allow-remote and lacks it, or "".
std::string remoteBindRefusal(const std::string &address, bool allowRemote);

// A file name for Content-Disposition: letters, digits, '-', '_' and '.', others become
// '_', no leading '.', at most 80 characters; `fallback` when nothing is left.
std::string safeFileName(std::string_view name, const std::string &fallback);

// Whether `value` may go into an HTTP header as is: printable ASCII and tabs only (no
// CR or LF that would end the header and start another).
bool headerSafe(std::string_view value);

// At most `lines` messages per `window` for one kind of event; then one line saying how
// many were left out. Thread-safe. Every message is cut to kMaxLogChars and escaped.
class LogLimiter {
public:
    static constexpr size_t kMaxLogChars = 160;
    LogLimiter(size_t lines, std::chrono::steady_clock::duration window) : lines_(lines), window_(window) {}
    // True when this event may be logged now; `suppressed` receives how many events were
    // left out since the last one logged (to say so in that line).
    bool allow(size_t &suppressed);

private:
    std::mutex mutex_;
    size_t lines_, used_ = 0, suppressed_ = 0;
    std::chrono::steady_clock::duration window_;
    std::chrono::steady_clock::time_point start_{};
};

// `text` as a log line may quote it: escaped and cut (sdk::printable).
std::string logExcerpt(std::string_view text);

} // namespace binocle::viewer
