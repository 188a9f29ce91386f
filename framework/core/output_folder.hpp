// SPDX-License-Identifier: MIT
// Who may write into an output folder: one process at a time (a lock), and only into a
// folder that holds no other kind of output unless the user asked to replace it.
#pragma once

#include <string>
#include <vector>

namespace binocle {

// The kinds of output, one per command that writes a folder. A folder belongs to the
// command that made it: OutputFolder marks it (DIR/.binocle-output: the kind and the
// command) and refuses, unless forced, a folder that holds anything else: another kind, a
// folder Binocle did not make (the user's own files), or one written before the marker
// existed (recognised by the files each command writes first, and named in the refusal).
enum class OutputKind {
    None,       // a lock only: the caller checks what the folder holds (binocle report into an experiment's folder)
    Run,        // `binocle run`, binocle.Rig.run(out=): frames.jsonl
    Recording,  // `binocle record`: frames.csv, or a rosbag2 bag (metadata.yaml, *.mcap)
    Experiment, // `binocle experiment` / `experiment merge`, binocle.experiment(out=): results.json or results.csv
    Design,     // `binocle design --out`: design.json, design.csv (and simulated/)
    View,       // `binocle view --out`: the viewer's snapshots
};

// "a recording", for messages.
std::string describe(OutputKind kind);

// The kind of output `dir` holds: its marker's, else recognised by its files (None when it
// does not exist, is empty, or holds nothing Binocle writes).
OutputKind outputKindOf(const std::string &dir);

// What `dir` holds, for a refusal: "a recording (frames.csv), made by binocle record", or
// "files Binocle did not write: notes.txt, results.csv". Empty when it holds nothing.
std::string describeContent(const std::string &dir);

// The entries of `dir` but the lock and the marker of its owner, sorted; up to `max` of
// them joined with ", " (and how many there are when more).
std::vector<std::string> entriesOf(const std::string &dir);
std::string listEntries(const std::string &dir, size_t max = 4);

struct OutputClaim {
    OutputKind kind = OutputKind::None; // what the caller writes; None: lock only, any content
    // Replace a folder that holds anything but this kind's output: its entries are removed first.
    bool force = false;
    std::string command; // "binocle run", written beside the pid for whoever finds the lock
    // How the caller's user asks for `force`, for the refusal: "--force", or Python's "force=True".
    std::string force_flag = "--force";
};

// Owns an output folder while alive: the folder is created if needed and locked
// (flock on DIR/.binocle-lock, which holds the owner's pid and command); the lock
// goes with the process, so a killed owner never leaves a stale one. Refuses, naming the
// folder and the owner's pid, a folder another process owns. With a kind: refuses a folder
// that holds anything but what this kind's command made there (its marker) unless `force`,
// naming the folder, what it holds and the flag; then marks the folder as this kind's.
class OutputFolder {
public:
    static constexpr const char *kLockFile = ".binocle-lock";
    static constexpr const char *kMarkerFile = ".binocle-output"; // "<kind> <command>"

    OutputFolder(const std::string &dir, const OutputClaim &claim);
    ~OutputFolder(); // removes the lock file, then lets go
    OutputFolder(const OutputFolder &) = delete;
    OutputFolder &operator=(const OutputFolder &) = delete;

    const std::string &dir() const { return dir_; }

private:
    void lock(const std::string &command);
    void checkKind(const OutputClaim &claim);
    void mark(const OutputClaim &claim);
    void release();
    std::string dir_;
    std::string lockPath_;
    int fd_ = -1;
    // Made by this claim (DIR and its missing parents, deepest first): removed again when
    // DIR ends empty (a refused run, a view without a snapshot, leave nothing).
    std::vector<std::string> created_;
};

} // namespace binocle
