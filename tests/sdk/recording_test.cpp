// SPDX-License-Identifier: MIT
// binocle/recording.hpp, the recording format shared by `binocle record` and `replay`,
// built here against the SDK alone (no framework source): rows written are rows read,
// a row cut short at the end is dropped and said, every other bad row is refused with
// its line, and no path may lead out of the recording.
#include <binocle/recording.hpp>

#include <gtest/gtest.h>

#include <cstdio>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace rec = binocle::recording;
namespace fs = std::filesystem;

namespace {

std::string refusal(const std::string &text) {
    try {
        rec::parseIndex(text, "frames.csv");
    } catch (const binocle::sdk::Error &e) {
        EXPECT_EQ(e.code(), BINOCLE_ERR_INVALID_ARGUMENT);
        return e.what();
    }
    return "";
}

TEST(Recording, RowsWrittenAreRowsRead) {
    EXPECT_EQ(rec::imagePath(0, 42), "left/000042.png");
    EXPECT_EQ(rec::imagePath(1, 1234567), "right/1234567.png");
    std::string text = rec::kIndexHeader;
    for (uint64_t s : {0ull, 1ull, 7ull, 9000000000ull}) text += rec::formatRow(rec::rowFor(s, 100 + int64_t(s), -5));
    const rec::Index index = rec::parseIndex(text, "frames.csv");
    ASSERT_EQ(index.rows.size(), 4u);
    EXPECT_TRUE(index.dropped_last.empty());
    EXPECT_EQ(index.rows[3].sequence, 9000000000);
    EXPECT_EQ(index.rows[3].timestamp_left_ns, 9000000100);
    EXPECT_EQ(index.rows[3].timestamp_right_ns, -5);
    EXPECT_EQ(index.rows[3].left, "left/9000000000.png");
    EXPECT_EQ(index.rows[3].line, 5);
    // Columns in any order, CRLF and blank lines are fine.
    const rec::Index other = rec::parseIndex("left,right,sequence,timestamp_right_ns,timestamp_left_ns\r\n\r\n"
                                             "a.png,b.png,3,2,1\r\n",
                                             "x.csv");
    ASSERT_EQ(other.rows.size(), 1u);
    EXPECT_EQ(other.rows[0].timestamp_left_ns, 1);
    EXPECT_EQ(other.rows[0].right, "b.png");
    // A UTF-8 byte order mark (a spreadsheet's "CSV UTF-8") is not part of the first name.
    const rec::Index bom = rec::parseIndex("\xEF\xBB\xBF" + std::string(rec::kIndexHeader) + "7,1,2,l.png,r.png\n", "bom.csv");
    ASSERT_EQ(bom.rows.size(), 1u);
    EXPECT_EQ(bom.rows[0].sequence, 7);
    EXPECT_EQ(bom.rows[0].line, 2);
}

TEST(Recording, ALastRowCutShortIsDroppedAndSaidOthersAreRefused) {
    const std::string head = std::string(rec::kIndexHeader) + rec::formatRow(rec::rowFor(0, 1, 1));
    const rec::Index cut = rec::parseIndex(head + "1,2,3,left/0000", "frames.csv");
    EXPECT_EQ(cut.rows.size(), 1u);
    EXPECT_EQ(cut.dropped_last, "frames.csv:3 is incomplete (4 fields; expected 5)");
    EXPECT_EQ(refusal(head + "1,2,3,left/x.png\n" + rec::formatRow(rec::rowFor(2, 1, 1))),
              "frames.csv:3: '1,2,3,left/x.png': 4 fields; expected 5");
    EXPECT_NE(refusal(head + "0640,1,1,l.png,r.png\n" + head.substr(head.find('\n') + 1)).find("leading zeros"), std::string::npos);
    EXPECT_NE(refusal(head + "-1,1,1,l.png,r.png\n" + head.substr(head.find('\n') + 1)).find("expected an integer >= 0"),
              std::string::npos);
    // A path out of the folder is refused even on the last line.
    EXPECT_NE(refusal(head + "5,1,1,../../etc/passwd,r.png\n").find("'..' leads out of the folder"), std::string::npos);
    EXPECT_NE(refusal(head + "5,1,1,/etc/passwd,r.png\n").find("absolute path"), std::string::npos);
    EXPECT_EQ(refusal(""), "'frames.csv' is empty; expected a header line");
    EXPECT_NE(refusal("sequence,left,right\n").find("has no column 'timestamp_left_ns'"), std::string::npos);
    EXPECT_NE(refusal("sequence,sequence,timestamp_left_ns,timestamp_right_ns,left,right\n").find("names column 'sequence' twice"),
              std::string::npos);
}

TEST(Recording, RowsAreAppendedDurablyAfterTheirFolders) {
    const fs::path dir = fs::temp_directory_path() / ("binocle-recording-test-" + std::to_string(::getpid()));
    fs::create_directories(dir / rec::kSideFolders[0]);
    fs::create_directories(dir / rec::kSideFolders[1]);
    const std::string index = (dir / rec::kIndexFile).string();
    const int fd = ::open(index.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    ASSERT_GE(fd, 0);
    int folders[2] = {::open((dir / "left").c_str(), O_RDONLY | O_DIRECTORY), ::open((dir / "right").c_str(), O_RDONLY | O_DIRECTORY)};
    rec::appendDurably(fd, rec::kIndexHeader, index);
    rec::appendRowsDurably(fd, folders, {rec::rowFor(3, 10, 11), rec::rowFor(4, 20, 21)}, dir.string());
    std::ostringstream text;
    text << std::ifstream(index).rdbuf();
    EXPECT_EQ(text.str(), std::string(rec::kIndexHeader) + "3,10,11,left/000003.png,right/000003.png\n"
                                                           "4,20,21,left/000004.png,right/000004.png\n");
    // A folder descriptor that is not open: the error names the folder.
    int bad[2] = {-1, -1};
    try {
        rec::appendRowsDurably(fd, bad, {rec::rowFor(5, 0, 0)}, dir.string());
        ADD_FAILURE() << "fsync of a closed descriptor passed";
    } catch (const binocle::sdk::Error &e) {
        EXPECT_EQ(e.code(), BINOCLE_ERR_IO);
        EXPECT_NE(std::string(e.what()).find(dir.string() + "/left: fsync failed"), std::string::npos) << e.what();
    }
    for (int f : {fd, folders[0], folders[1]}) ::close(f);
    fs::remove_all(dir);
}

} // namespace
