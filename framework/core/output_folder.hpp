// SPDX-License-Identifier: MIT
// Who may write into an output folder: one process at a time (a lock), and only into a
// folder that holds no other kind of output unless the user asked to replace it.
#pragma once

#include <string>

namespace binocle {

// What a folder holds, recognised by the files each command writes first (so folders
// written before the lock existed are recognised too).
enum class OutputKind {
    None,       // empty, or holds nothing Binocle wrote
    Run,        // `binocle run`: frames.jsonl
    Recording,  // `binocle record`: frames.csv
    Experiment, // `binocle experiment` / `experiment merge`: results.json or results.csv
};

// "a recording (frames.csv)", for messages.
std::string describe(OutputKind kind);

// The kind of output `dir` holds (None when it does not exist).
OutputKind outputKindOf(const std::string &dir);

struct OutputClaim {
    OutputKind kind = OutputKind::None; // what the caller writes; None: lock only, any content
    // Replace a folder that holds another kind of output: its entries are removed first.
    bool force = false;
    std::string command; // "binocle run", written beside the pid for whoever finds the lock
};

// Owns an output folder while alive: the folder is created if needed and locked
// (flock on DIR/.binocle-lock, which holds the owner's pid and command); the lock
// goes with the process, so a killed owner never leaves a stale one. Refuses, naming the
// folder and the owner's pid, a folder another process owns; refuses a folder holding
// another kind of output unless `force`, naming what it holds.
class OutputFolder {
public:
    static constexpr const char *kLockFile = ".binocle-lock";

    OutputFolder(const std::string &dir, const OutputClaim &claim);
    ~OutputFolder(); // removes the lock file, then lets go
    OutputFolder(const OutputFolder &) = delete;
    OutputFolder &operator=(const OutputFolder &) = delete;

    const std::string &dir() const { return dir_; }

private:
    void lock(const std::string &command);
    void checkKind(const OutputClaim &claim);
    void release();
    std::string dir_;
    std::string lockPath_;
    int fd_ = -1;
    bool created_ = false; // made by this claim: removed again when it ends empty (a refused run leaves nothing)
};

} // namespace binocle
