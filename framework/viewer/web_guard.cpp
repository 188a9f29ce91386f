// SPDX-License-Identifier: MIT
// The viewer's request checks: Host and Origin rules, binds, download names, log limits.
#include "viewer/web_guard.hpp"

#include <binocle/text.hpp>
#include <boost/asio/ip/address.hpp>

#include <algorithm>
#include <optional>

namespace binocle::viewer {

namespace {

namespace ip = boost::asio::ip;

struct HostPort {
    std::string name; // lowercased; an IPv6 literal without its brackets
    std::string port; // "" when the header names none
};

std::string lower(std::string_view s) {
    std::string out(s);
    for (char &c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
}

bool allDigits(std::string_view s) {
    return !s.empty() && s.size() <= 5 && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// "name", "name:port", "[v6]", "[v6]:port"; an unbracketed IPv6 literal ("::1") has no
// port. Nothing when the text is not of that shape.
std::optional<HostPort> splitHost(std::string_view host) {
    if (host.empty() || host.size() > 255) return std::nullopt;
    for (const char c : host)
        if (static_cast<unsigned char>(c) <= 0x20 || static_cast<unsigned char>(c) >= 0x7F || c == '/' || c == '@')
            return std::nullopt;
    HostPort out;
    if (host.front() == '[') {
        const size_t close = host.find(']');
        if (close == std::string_view::npos) return std::nullopt;
        const std::string_view rest = host.substr(close + 1);
        if (!rest.empty()) {
            if (rest[0] != ':' || !allDigits(rest.substr(1))) return std::nullopt;
            out.port = std::string(rest.substr(1));
        }
        out.name = lower(host.substr(1, close - 1));
    } else if (const size_t colon = host.find(':'); colon != std::string_view::npos && host.find(':', colon + 1) == std::string_view::npos) {
        if (!allDigits(host.substr(colon + 1))) return std::nullopt;
        out.name = lower(host.substr(0, colon));
        out.port = std::string(host.substr(colon + 1));
    } else {
        out.name = lower(host);
    }
    if (out.name.empty()) return std::nullopt;
    return out;
}

// The address an IP literal names, IPv4-mapped IPv6 as IPv4; nothing for a name.
std::optional<ip::address> literal(const std::string &text) {
    boost::system::error_code ec;
    ip::address a = ip::make_address(text, ec);
    if (ec) return std::nullopt;
    if (a.is_v6() && a.to_v6().is_v4_mapped()) a = ip::make_address_v4(ip::v4_mapped, a.to_v6());
    return a;
}

bool loopback(const ip::address &a) { return a.is_loopback(); }

} // namespace

bool isLoopbackAddress(const std::string &address) {
    const auto a = literal(address);
    return a && loopback(*a);
}

bool hostAllowed(std::string_view host, const std::string &localAddress, const std::vector<std::string> &allowedNames) {
    const auto h = splitHost(host);
    const auto local = literal(localAddress);
    if (!h || !local) return false;
    const bool onLoopback = loopback(*local);
    if (const auto named = literal(h->name)) return *named == *local || (onLoopback && loopback(*named));
    if (onLoopback && h->name == "localhost") return true;
    return std::any_of(allowedNames.begin(), allowedNames.end(), [&](const std::string &n) { return lower(n) == h->name; });
}

bool sameOrigin(std::string_view origin, std::string_view host) {
    constexpr std::string_view scheme = "http://";
    const std::string o = lower(origin);
    if (o.compare(0, scheme.size(), scheme) != 0) return false;
    const auto a = splitHost(std::string_view(o).substr(scheme.size()));
    const auto b = splitHost(host);
    if (!a || !b) return false;
    const auto port = [](const HostPort &x) { return x.port.empty() ? std::string("80") : x.port; };
    return a->name == b->name && port(*a) == port(*b);
}

std::string remoteBindRisk(const std::string &address) {
    const auto a = literal(address);
    if (!a || loopback(*a)) return ""; // not an address at all: the server says so when it binds
    const std::string where = a->is_unspecified() ? "every network this machine is on" : "the network of " + address;
    return "--bind " + address + " serves the page and its controls to " + where +
           ": the token in the URL travels unencrypted (plain HTTP), and whoever has it may change settings and "
           "write snapshots as this user";
}

std::string remoteBindRefusal(const std::string &address, bool allowRemote) {
    const std::string risk = remoteBindRisk(address);
    if (risk.empty() || allowRemote) return "";
    return risk + ". Add --allow-remote to serve it anyway, or leave --bind at 127.0.0.1 and reach it through an SSH tunnel "
                  "(docs/security.md)";
}

std::string safeFileName(std::string_view name, const std::string &fallback) {
    std::string out;
    for (const char c : name) {
        if (out.size() >= 80) break;
        const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.';
        out += ok ? c : '_';
    }
    while (!out.empty() && out.front() == '.') out.erase(0, 1);
    return out.find_first_not_of("._") == std::string::npos ? fallback : out;
}

bool headerSafe(std::string_view value) {
    return std::all_of(value.begin(), value.end(), [](char c) {
        const auto u = static_cast<unsigned char>(c);
        return u == '\t' || (u >= 0x20 && u < 0x7F);
    });
}

bool LogLimiter::allow(size_t &suppressed) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto now = std::chrono::steady_clock::now();
    if (used_ == 0 || now - start_ >= window_) {
        start_ = now;
        used_ = 0;
    }
    if (used_ >= lines_) {
        ++suppressed_;
        return false;
    }
    ++used_;
    suppressed = suppressed_;
    suppressed_ = 0;
    return true;
}

std::string logExcerpt(std::string_view text) { return sdk::printable(text, LogLimiter::kMaxLogChars); }

} // namespace binocle::viewer
