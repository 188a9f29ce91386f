// SPDX-License-Identifier: MIT
// Fuzz harness: what a page or a stranger sends the viewer. The command parser
// (viewer/command.hpp) must refuse or accept every text in time linear in its size, and
// what it accepts must respect the caps; the same bytes as a Host or Origin header and as
// a download name must never admit a header break or a non-local name.
#include "viewer/command.hpp"
#include "viewer/web_guard.hpp"

#include <cstdint>
#include <cstdlib>
#include <string>

using namespace binocle::viewer;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    const std::string text(reinterpret_cast<const char *>(data), size);
    try {
        const Command c = parseCommand(text);
        if (text.size() > kMaxCommandBytes) std::abort();
        if (c.op == Op::Set) {
            if (c.key.empty() || c.key.size() > kMaxKeyBytes || c.value.size() > kMaxValueBytes) std::abort();
            size_t parts = 1;
            for (const char ch : c.key) {
                if (ch == '.') ++parts;
                else if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '_') std::abort();
            }
            if (parts > kMaxKeyParts || c.key.front() == '.' || c.key.back() == '.' || c.key.find("..") != std::string::npos)
                std::abort();
        } else if (!c.key.empty() || !c.value.empty()) {
            std::abort();
        }
    } catch (const CommandError &e) {
        // The message quotes at most an excerpt of what was sent.
        if (std::string(e.what()).size() > 400) std::abort();
    }

    // The same bytes as headers and names.
    const std::string name = safeFileName(text, "x");
    if (name.empty() || name.size() > 80 || !headerSafe(name) || name.front() == '.' || name.find('"') != std::string::npos)
        std::abort();
    // A Host served on loopback with no --allow-host is "localhost" or an IP literal
    // ([::1], 127.x), with a port at most: no space, control character, '/' or '@'.
    if (hostAllowed(text, "127.0.0.1", {})) {
        for (const char ch : text)
            if (static_cast<unsigned char>(ch) <= 0x20 || ch == '/' || ch == '@' || static_cast<unsigned char>(ch) >= 0x7F) std::abort();
        std::string lower;
        for (const char ch : text) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
        const char first = lower.empty() ? 0 : lower[0];
        if (lower.rfind("localhost", 0) != 0 && !(first >= '0' && first <= '9') && first != '[' && first != ':') std::abort();
    }
    (void)sameOrigin(text, "127.0.0.1:8080");
    (void)logExcerpt(text);
    return 0;
}
