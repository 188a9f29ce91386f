// SPDX-License-Identifier: MIT
// ROS 2 messages without ROS: the types a stereo head publishes and Binocle writes, their
// `ros2msg` definitions (with every dependent definition, as `ros2 bag record` stores them
// in an MCAP schema), and their CDR encoding (XCDR1 little-endian, the 4-byte encapsulation
// header, fields aligned to their size from the end of that header), as rmw_fastrtps and
// rmw_cyclonedds put them on the wire.
//
// Library: Binocle::mcap, with <binocle/mcap.hpp>.
// Decoding is strict: every length is checked against the bytes left before anything is
// allocated, and a fault throws ros2::Error naming the message type and the field.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace binocle::ros2 {

class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// ---- CDR ---------------------------------------------------------------------------------

// Appends fields, aligned from the end of the encapsulation header.
class CdrWriter {
public:
    CdrWriter();
    void u8(uint8_t v);
    void u16(uint16_t v);
    void i32(int32_t v);
    void u32(uint32_t v);
    void f32(float v);
    void f64(double v);
    void str(const std::string &s);
    void bytes(const uint8_t *data, size_t size); // a uint8[] sequence
    void f64s(const double *v, size_t n);         // float64[n] (fixed: no length)
    const std::vector<uint8_t> &data() const { return b_; }
    std::vector<uint8_t> &data() { return b_; }

private:
    void align(size_t n);
    std::vector<uint8_t> b_;
};

class CdrReader {
public:
    // Checks the encapsulation header (CDR little- or big-endian); `type` names errors.
    CdrReader(const uint8_t *data, size_t size, std::string type);
    uint8_t u8(const char *field);
    uint16_t u16(const char *field);
    int32_t i32(const char *field);
    uint32_t u32(const char *field);
    float f32(const char *field);
    double f64(const char *field);
    std::string str(const char *field);
    // A uint8[] sequence: its length, and where its bytes are (not copied).
    const uint8_t *bytes(const char *field, size_t &size);
    // A sequence count whose elements take at least `minElementBytes` each; checked
    // against the bytes left.
    uint32_t count(const char *field, size_t minElementBytes);
    size_t left() const { return n_ - i_; }

private:
    void align(size_t n);
    void need(size_t k, const char *field) const;
    template <typename T> T get(const char *field);
    const uint8_t *p_;
    size_t n_, i_ = 4;
    bool bigEndian_ = false;
    std::string type_;
};

// ---- Messages ----------------------------------------------------------------------------

struct Time {
    int32_t sec = 0;
    uint32_t nanosec = 0;
    int64_t ns() const { return int64_t{sec} * 1000000000 + nanosec; }
    static Time fromNs(int64_t ns);
};

struct Header { // std_msgs/msg/Header
    Time stamp;
    std::string frame_id;
};

struct RegionOfInterest { // sensor_msgs/msg/RegionOfInterest
    uint32_t x_offset = 0, y_offset = 0, height = 0, width = 0;
    bool do_rectify = false;
};

// sensor_msgs/msg/Image. Decoded, `data` points into the message bytes (valid while they
// are); encoded, it is copied in.
struct Image {
    static constexpr const char *kType = "sensor_msgs/msg/Image";
    Header header;
    uint32_t height = 0, width = 0;
    std::string encoding; // mono8, mono16, rgb8, bgr8, bayer_rggb8, 32FC1 ...
    uint8_t is_bigendian = 0;
    uint32_t step = 0;
    const uint8_t *data = nullptr;
    size_t size = 0;

    // Bytes per pixel of `encoding` (0 when unknown).
    static int bytesPerPixel(const std::string &encoding);
    // Throws ros2::Error unless step >= width * bytesPerPixel and size == step * height.
    void checkLayout(const std::string &where) const;
};

struct CompressedImage { // sensor_msgs/msg/CompressedImage
    static constexpr const char *kType = "sensor_msgs/msg/CompressedImage";
    Header header;
    std::string format; // "jpeg", "png", "mono8; jpeg compressed mono8" ...
    const uint8_t *data = nullptr;
    size_t size = 0;
};

struct CameraInfo { // sensor_msgs/msg/CameraInfo
    static constexpr const char *kType = "sensor_msgs/msg/CameraInfo";
    Header header;
    uint32_t height = 0, width = 0;
    std::string distortion_model = "plumb_bob";
    std::vector<double> d;
    std::array<double, 9> k{};
    std::array<double, 9> r{};
    std::array<double, 12> p{};
    uint32_t binning_x = 0, binning_y = 0;
    RegionOfInterest roi;
};

struct PointField { // sensor_msgs/msg/PointField
    enum : uint8_t { INT8 = 1, UINT8 = 2, INT16 = 3, UINT16 = 4, INT32 = 5, UINT32 = 6, FLOAT32 = 7, FLOAT64 = 8 };
    std::string name;
    uint32_t offset = 0;
    uint8_t datatype = FLOAT32;
    uint32_t count = 1;
};

struct PointCloud2 { // sensor_msgs/msg/PointCloud2
    static constexpr const char *kType = "sensor_msgs/msg/PointCloud2";
    Header header;
    uint32_t height = 1, width = 0;
    std::vector<PointField> fields;
    bool is_bigendian = false;
    uint32_t point_step = 0, row_step = 0;
    const uint8_t *data = nullptr;
    size_t size = 0;
    bool is_dense = false;
};

struct DisparityImage { // stereo_msgs/msg/DisparityImage
    static constexpr const char *kType = "stereo_msgs/msg/DisparityImage";
    Header header;
    Image image; // 32FC1
    float f = 0, t = 0; // focal length (px) and baseline (m): depth Z = f T / d
    RegionOfInterest valid_window;
    float min_disparity = 0, max_disparity = 0, delta_d = 0;
};

// diagnostic_msgs/msg/DiagnosticArray: Binocle's evaluator figures, one status per
// evaluator, one key/value per figure.
struct DiagnosticStatus {
    enum : uint8_t { OK = 0, WARN = 1, ERROR = 2, STALE = 3 };
    uint8_t level = OK;
    std::string name, message, hardware_id;
    std::vector<std::pair<std::string, std::string>> values;
};
struct DiagnosticArray {
    static constexpr const char *kType = "diagnostic_msgs/msg/DiagnosticArray";
    Header header;
    std::vector<DiagnosticStatus> status;
};

// The `ros2msg` schema text of a type above: its definition, then each dependency after a
// line of 80 '=' and "MSG: pkg/Type", as rosbag2 writes it. Throws for another type.
const std::string &definition(const std::string &type);

std::vector<uint8_t> encode(const Image &m);
std::vector<uint8_t> encode(const CompressedImage &m);
std::vector<uint8_t> encode(const CameraInfo &m);
std::vector<uint8_t> encode(const PointCloud2 &m);
std::vector<uint8_t> encode(const DisparityImage &m);
std::vector<uint8_t> encode(const DiagnosticArray &m);

// Decoders: `data` must outlive the views into it (Image::data ...).
Image decodeImage(const uint8_t *data, size_t size);
CompressedImage decodeCompressedImage(const uint8_t *data, size_t size);
CameraInfo decodeCameraInfo(const uint8_t *data, size_t size);
PointCloud2 decodePointCloud2(const uint8_t *data, size_t size);
DisparityImage decodeDisparityImage(const uint8_t *data, size_t size);
DiagnosticArray decodeDiagnosticArray(const uint8_t *data, size_t size);
// Only the header (the first field of every type above): cheap, for pairing by stamp.
Header decodeHeader(const uint8_t *data, size_t size, const std::string &type);

// ---- Stereo calibration <-> CameraInfo -----------------------------------------------------

// A stereo pair's calibration in Binocle's terms (framework/core/calibration.hpp: lengths in
// mm, x_r = R x_l + T) without OpenCV: row-major arrays.
struct StereoCameraModel {
    uint32_t width = 0, height = 0;
    std::array<double, 9> M1{}, M2{};
    std::vector<double> D1, D2;
    std::array<double, 9> R{}, R1{}, R2{};
    std::array<double, 3> T{}; // mm
    std::array<double, 12> P1{}, P2{}; // P2(0,3) = fx' Tx, Tx in mm (negative: right of left)
};

// CameraInfo of each side (plumb_bob; P in metres, as ROS has it: P2(0,3) = -fx' B).
std::array<CameraInfo, 2> cameraInfos(const StereoCameraModel &model);
// The pair back from the CameraInfo of each side; throws ros2::Error naming `where` and the
// field unless both are consistent (sizes, positive focal lengths, a right P with Tx != 0).
StereoCameraModel stereoModel(const CameraInfo &left, const CameraInfo &right, const std::string &where);

} // namespace binocle::ros2
