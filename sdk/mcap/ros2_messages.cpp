// SPDX-License-Identifier: MIT
// ROS 2 messages: CDR encoding and decoding, the ros2msg definitions, and the stereo
// calibration <-> CameraInfo conversion (see <binocle/ros2_messages.hpp>).
#include <binocle/ros2_messages.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>

namespace binocle::ros2 {

// ---- CDR ---------------------------------------------------------------------------------

CdrWriter::CdrWriter() : b_{0x00, 0x01, 0x00, 0x00} {} // CDR_LE, options 0

void CdrWriter::align(size_t n) {
    while ((b_.size() - 4) % n != 0) b_.push_back(0);
}
void CdrWriter::u8(uint8_t v) { b_.push_back(v); }
void CdrWriter::u16(uint16_t v) {
    align(2);
    b_.push_back(static_cast<uint8_t>(v));
    b_.push_back(static_cast<uint8_t>(v >> 8));
}
void CdrWriter::u32(uint32_t v) {
    align(4);
    for (int i = 0; i < 4; ++i) b_.push_back(static_cast<uint8_t>(v >> (8 * i)));
}
void CdrWriter::i32(int32_t v) { u32(static_cast<uint32_t>(v)); }
void CdrWriter::f32(float v) {
    uint32_t u;
    std::memcpy(&u, &v, 4);
    u32(u);
}
void CdrWriter::f64(double v) {
    uint64_t u;
    std::memcpy(&u, &v, 8);
    align(8);
    for (int i = 0; i < 8; ++i) b_.push_back(static_cast<uint8_t>(u >> (8 * i)));
}
void CdrWriter::str(const std::string &s) {
    u32(static_cast<uint32_t>(s.size() + 1)); // with its terminating NUL
    b_.insert(b_.end(), s.begin(), s.end());
    b_.push_back(0);
}
void CdrWriter::bytes(const uint8_t *data, size_t size) {
    u32(static_cast<uint32_t>(size));
    if (size) b_.insert(b_.end(), data, data + size);
}
void CdrWriter::f64s(const double *v, size_t n) {
    for (size_t i = 0; i < n; ++i) f64(v[i]);
}

CdrReader::CdrReader(const uint8_t *data, size_t size, std::string type) : p_(data), n_(size), type_(std::move(type)) {
    if (size < 4) throw Error(type_ + ": " + std::to_string(size) + " bytes; expected at least the 4-byte CDR header");
    // 0x0000 CDR_BE, 0x0001 CDR_LE (XCDR1); the PL_CDR forms are not used by ROS 2 messages.
    if (data[0] != 0 || (data[1] != 0 && data[1] != 1))
        throw Error(type_ + ": encapsulation " + std::to_string(data[0]) + "," + std::to_string(data[1]) +
                    "; expected CDR (0,0 big-endian or 0,1 little-endian)");
    bigEndian_ = data[1] == 0;
}
void CdrReader::need(size_t k, const char *field) const {
    if (k > n_ - i_)
        throw Error(type_ + ": field " + field + " needs " + std::to_string(k) + " bytes but the message has " +
                    std::to_string(n_ - i_) + " left (at byte " + std::to_string(i_) + ")");
}
void CdrReader::align(size_t n) {
    const size_t pad = (n - (i_ - 4) % n) % n;
    i_ += std::min(pad, n_ - i_);
}
template <typename T> T CdrReader::get(const char *field) {
    align(sizeof(T));
    need(sizeof(T), field);
    uint64_t v = 0;
    for (size_t k = 0; k < sizeof(T); ++k) {
        const size_t byte = bigEndian_ ? sizeof(T) - 1 - k : k;
        v |= static_cast<uint64_t>(p_[i_ + k]) << (8 * byte);
    }
    i_ += sizeof(T);
    T out;
    if constexpr (sizeof(T) == 8) {
        uint64_t u = v;
        std::memcpy(&out, &u, 8);
    } else if constexpr (sizeof(T) == 4) {
        auto u = static_cast<uint32_t>(v);
        std::memcpy(&out, &u, 4);
    } else if constexpr (sizeof(T) == 2) {
        auto u = static_cast<uint16_t>(v);
        std::memcpy(&out, &u, 2);
    } else {
        out = static_cast<T>(v);
    }
    return out;
}
uint8_t CdrReader::u8(const char *f) { return get<uint8_t>(f); }
uint16_t CdrReader::u16(const char *f) { return get<uint16_t>(f); }
int32_t CdrReader::i32(const char *f) { return get<int32_t>(f); }
uint32_t CdrReader::u32(const char *f) { return get<uint32_t>(f); }
float CdrReader::f32(const char *f) { return get<float>(f); }
double CdrReader::f64(const char *f) { return get<double>(f); }
std::string CdrReader::str(const char *field) {
    const uint32_t len = u32(field);
    need(len, field);
    // The length counts the NUL; a length of 0 is tolerated as the empty string.
    std::string s(reinterpret_cast<const char *>(p_ + i_), len > 0 ? len - 1 : 0);
    if (len > 0 && p_[i_ + len - 1] != 0)
        throw Error(type_ + ": string " + field + " of " + std::to_string(len) + " bytes does not end with NUL");
    i_ += len;
    return s;
}
const uint8_t *CdrReader::bytes(const char *field, size_t &size) {
    const uint32_t len = u32(field);
    need(len, field);
    const uint8_t *at = p_ + i_;
    i_ += len;
    size = len;
    return at;
}
uint32_t CdrReader::count(const char *field, size_t minElementBytes) {
    const uint32_t n = u32(field);
    if (minElementBytes > 0 && n > (n_ - i_) / minElementBytes)
        throw Error(type_ + ": sequence " + field + " claims " + std::to_string(n) + " elements of at least " +
                    std::to_string(minElementBytes) + " bytes but the message has " + std::to_string(n_ - i_) + " left");
    return n;
}

// ---- Definitions -------------------------------------------------------------------------

namespace {

const std::map<std::string, std::string> &plainDefinitions() {
    static const std::map<std::string, std::string> defs{
        {"builtin_interfaces/Time", "int32 sec\nuint32 nanosec\n"},
        {"std_msgs/Header", "builtin_interfaces/Time stamp\nstring frame_id\n"},
        {"sensor_msgs/RegionOfInterest", "uint32 x_offset\nuint32 y_offset\nuint32 height\nuint32 width\nbool do_rectify\n"},
        {"sensor_msgs/Image", "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\n"
                              "uint32 step\nuint8[] data\n"},
        {"sensor_msgs/CompressedImage", "std_msgs/Header header\nstring format\nuint8[] data\n"},
        {"sensor_msgs/CameraInfo", "std_msgs/Header header\nuint32 height\nuint32 width\nstring distortion_model\n"
                                   "float64[] d\nfloat64[9] k\nfloat64[9] r\nfloat64[12] p\nuint32 binning_x\n"
                                   "uint32 binning_y\nsensor_msgs/RegionOfInterest roi\n"},
        {"sensor_msgs/PointField", "uint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\nuint8 INT32=5\n"
                                   "uint8 UINT32=6\nuint8 FLOAT32=7\nuint8 FLOAT64=8\nstring name\nuint32 offset\n"
                                   "uint8 datatype\nuint32 count\n"},
        {"sensor_msgs/PointCloud2", "std_msgs/Header header\nuint32 height\nuint32 width\nsensor_msgs/PointField[] fields\n"
                                    "bool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n"},
        {"stereo_msgs/DisparityImage", "std_msgs/Header header\nsensor_msgs/Image image\nfloat32 f\nfloat32 t\n"
                                       "sensor_msgs/RegionOfInterest valid_window\nfloat32 min_disparity\n"
                                       "float32 max_disparity\nfloat32 delta_d\n"},
        {"diagnostic_msgs/KeyValue", "string key\nstring value\n"},
        {"diagnostic_msgs/DiagnosticStatus", "byte OK=0\nbyte WARN=1\nbyte ERROR=2\nbyte STALE=3\nbyte level\nstring name\n"
                                             "string message\nstring hardware_id\ndiagnostic_msgs/KeyValue[] values\n"},
        {"diagnostic_msgs/DiagnosticArray", "std_msgs/Header header\ndiagnostic_msgs/DiagnosticStatus[] status\n"},
    };
    return defs;
}

// The types a definition names, in order of first use, depth first (as rosbag2 lists them).
void dependencies(const std::string &type, std::vector<std::string> &out) {
    const std::string &text = plainDefinitions().at(type);
    size_t i = 0;
    while (i < text.size()) {
        const size_t eol = text.find('\n', i);
        const std::string line = text.substr(i, eol - i);
        i = eol + 1;
        std::string field = line.substr(0, line.find(' '));
        if (const size_t b = field.find('['); b != std::string::npos) field = field.substr(0, b);
        if (field.find('/') == std::string::npos) continue;
        if (std::find(out.begin(), out.end(), field) != out.end()) continue;
        out.push_back(field);
        dependencies(field, out);
    }
}

} // namespace

const std::string &definition(const std::string &type) {
    static std::map<std::string, std::string> full;
    static const bool built = [] {
        for (const auto &[name, text] : plainDefinitions()) {
            std::string s = text;
            std::vector<std::string> deps;
            dependencies(name, deps);
            for (const std::string &d : deps)
                s += std::string(80, '=') + "\nMSG: " + d + "\n" + plainDefinitions().at(d);
            const size_t slash = name.find('/');
            full[name.substr(0, slash) + "/msg" + name.substr(slash)] = s;
        }
        return true;
    }();
    (void)built;
    auto it = full.find(type);
    if (it == full.end()) throw Error("ros2: no definition of message type '" + type + "'");
    return it->second;
}

// ---- Encoding ----------------------------------------------------------------------------

Time Time::fromNs(int64_t ns) {
    Time t;
    int64_t sec = ns / 1000000000, rem = ns % 1000000000;
    if (rem < 0) {
        rem += 1000000000;
        --sec;
    }
    t.sec = static_cast<int32_t>(sec);
    t.nanosec = static_cast<uint32_t>(rem);
    return t;
}

namespace {
void put(CdrWriter &w, const Header &h) {
    w.i32(h.stamp.sec);
    w.u32(h.stamp.nanosec);
    w.str(h.frame_id);
}
void put(CdrWriter &w, const RegionOfInterest &r) {
    w.u32(r.x_offset);
    w.u32(r.y_offset);
    w.u32(r.height);
    w.u32(r.width);
    w.u8(r.do_rectify ? 1 : 0);
}
// The header, height and width that Image, CameraInfo and PointCloud2 begin with.
template <class Message> void putSized(CdrWriter &w, const Message &m) {
    put(w, m.header);
    w.u32(m.height);
    w.u32(m.width);
}
// A sequence: its count, then `put` writes each element.
template <class T, class Put> void putSequence(CdrWriter &w, const std::vector<T> &v, Put put) {
    w.u32(static_cast<uint32_t>(v.size()));
    for (const T &e : v) put(e);
}
void put(CdrWriter &w, const Image &m) {
    putSized(w, m);
    w.str(m.encoding);
    w.u8(m.is_bigendian);
    w.u32(m.step);
    w.bytes(m.data, m.size);
}
Header getHeader(CdrReader &r) {
    Header h;
    h.stamp.sec = r.i32("header.stamp.sec");
    h.stamp.nanosec = r.u32("header.stamp.nanosec");
    h.frame_id = r.str("header.frame_id");
    return h;
}
RegionOfInterest getRoi(CdrReader &r) {
    RegionOfInterest o;
    o.x_offset = r.u32("roi.x_offset");
    o.y_offset = r.u32("roi.y_offset");
    o.height = r.u32("roi.height");
    o.width = r.u32("roi.width");
    o.do_rectify = r.u8("roi.do_rectify") != 0;
    return o;
}
template <class Message> void getSized(CdrReader &r, Message &m) {
    m.header = getHeader(r);
    m.height = r.u32("height");
    m.width = r.u32("width");
}
// A sequence: its count (each element takes at least `minElementBytes`, checked against
// the bytes left), then `get` reads each element in place.
template <class T, class Get>
void getSequence(CdrReader &r, const char *field, size_t minElementBytes, std::vector<T> &v, Get get) {
    v.resize(r.count(field, minElementBytes));
    for (T &e : v) get(e);
}
Image getImage(CdrReader &r) {
    Image m;
    getSized(r, m);
    m.encoding = r.str("encoding");
    m.is_bigendian = r.u8("is_bigendian");
    m.step = r.u32("step");
    m.data = r.bytes("data", m.size);
    return m;
}
} // namespace

std::vector<uint8_t> encode(const Image &m) {
    CdrWriter w;
    w.data().reserve(64 + m.encoding.size() + m.header.frame_id.size() + m.size);
    put(w, m);
    return std::move(w.data());
}

std::vector<uint8_t> encode(const CompressedImage &m) {
    CdrWriter w;
    w.data().reserve(64 + m.size);
    put(w, m.header);
    w.str(m.format);
    w.bytes(m.data, m.size);
    return std::move(w.data());
}

std::vector<uint8_t> encode(const CameraInfo &m) {
    CdrWriter w;
    putSized(w, m);
    w.str(m.distortion_model);
    w.u32(static_cast<uint32_t>(m.d.size()));
    w.f64s(m.d.data(), m.d.size());
    w.f64s(m.k.data(), 9);
    w.f64s(m.r.data(), 9);
    w.f64s(m.p.data(), 12);
    w.u32(m.binning_x);
    w.u32(m.binning_y);
    put(w, m.roi);
    return std::move(w.data());
}

std::vector<uint8_t> encode(const PointCloud2 &m) {
    CdrWriter w;
    w.data().reserve(256 + m.size);
    putSized(w, m);
    putSequence(w, m.fields, [&](const PointField &f) {
        w.str(f.name);
        w.u32(f.offset);
        w.u8(f.datatype);
        w.u32(f.count);
    });
    w.u8(m.is_bigendian ? 1 : 0);
    w.u32(m.point_step);
    w.u32(m.row_step);
    w.bytes(m.data, m.size);
    w.u8(m.is_dense ? 1 : 0);
    return std::move(w.data());
}

std::vector<uint8_t> encode(const DisparityImage &m) {
    CdrWriter w;
    w.data().reserve(128 + m.image.size);
    put(w, m.header);
    put(w, m.image);
    w.f32(m.f);
    w.f32(m.t);
    put(w, m.valid_window);
    w.f32(m.min_disparity);
    w.f32(m.max_disparity);
    w.f32(m.delta_d);
    return std::move(w.data());
}

std::vector<uint8_t> encode(const DiagnosticArray &m) {
    CdrWriter w;
    put(w, m.header);
    putSequence(w, m.status, [&](const DiagnosticStatus &s) {
        w.u8(s.level);
        w.str(s.name);
        w.str(s.message);
        w.str(s.hardware_id);
        putSequence(w, s.values, [&](const std::pair<std::string, std::string> &kv) {
            w.str(kv.first);
            w.str(kv.second);
        });
    });
    return std::move(w.data());
}

// ---- Decoding ----------------------------------------------------------------------------

Header decodeHeader(const uint8_t *data, size_t size, const std::string &type) {
    CdrReader r(data, size, type);
    return getHeader(r);
}

Image decodeImage(const uint8_t *data, size_t size) {
    CdrReader r(data, size, Image::kType);
    return getImage(r);
}

CompressedImage decodeCompressedImage(const uint8_t *data, size_t size) {
    CdrReader r(data, size, CompressedImage::kType);
    CompressedImage m;
    m.header = getHeader(r);
    m.format = r.str("format");
    m.data = r.bytes("data", m.size);
    return m;
}

CameraInfo decodeCameraInfo(const uint8_t *data, size_t size) {
    CdrReader r(data, size, CameraInfo::kType);
    CameraInfo m;
    getSized(r, m);
    m.distortion_model = r.str("distortion_model");
    getSequence(r, "d", 8, m.d, [&](double &v) { v = r.f64("d"); });
    for (double &v : m.k) v = r.f64("k");
    for (double &v : m.r) v = r.f64("r");
    for (double &v : m.p) v = r.f64("p");
    m.binning_x = r.u32("binning_x");
    m.binning_y = r.u32("binning_y");
    m.roi = getRoi(r);
    return m;
}

PointCloud2 decodePointCloud2(const uint8_t *data, size_t size) {
    CdrReader r(data, size, PointCloud2::kType);
    PointCloud2 m;
    getSized(r, m);
    getSequence(r, "fields", 13, m.fields, [&](PointField &f) {
        f.name = r.str("fields.name");
        f.offset = r.u32("fields.offset");
        f.datatype = r.u8("fields.datatype");
        f.count = r.u32("fields.count");
    });
    m.is_bigendian = r.u8("is_bigendian") != 0;
    m.point_step = r.u32("point_step");
    m.row_step = r.u32("row_step");
    m.data = r.bytes("data", m.size);
    m.is_dense = r.u8("is_dense") != 0;
    return m;
}

DisparityImage decodeDisparityImage(const uint8_t *data, size_t size) {
    CdrReader r(data, size, DisparityImage::kType);
    DisparityImage m;
    m.header = getHeader(r);
    m.image = getImage(r);
    m.f = r.f32("f");
    m.t = r.f32("t");
    m.valid_window = getRoi(r);
    m.min_disparity = r.f32("min_disparity");
    m.max_disparity = r.f32("max_disparity");
    m.delta_d = r.f32("delta_d");
    return m;
}

DiagnosticArray decodeDiagnosticArray(const uint8_t *data, size_t size) {
    CdrReader r(data, size, DiagnosticArray::kType);
    DiagnosticArray m;
    m.header = getHeader(r);
    getSequence(r, "status", 17, m.status, [&](DiagnosticStatus &s) {
        s.level = r.u8("status.level");
        s.name = r.str("status.name");
        s.message = r.str("status.message");
        s.hardware_id = r.str("status.hardware_id");
        getSequence(r, "status.values", 8, s.values, [&](std::pair<std::string, std::string> &kv) {
            kv.first = r.str("values.key");
            kv.second = r.str("values.value");
        });
    });
    return m;
}

// ---- Images --------------------------------------------------------------------------------

int Image::bytesPerPixel(const std::string &e) {
    if (e == "mono8" || e == "8UC1" || e.rfind("bayer_", 0) == 0) return e.size() > 2 && e.substr(e.size() - 2) == "16" ? 2 : 1;
    if (e == "mono16" || e == "16UC1") return 2;
    if (e == "rgb8" || e == "bgr8" || e == "8UC3") return 3;
    if (e == "rgba8" || e == "bgra8" || e == "8UC4") return 4;
    if (e == "32FC1") return 4;
    if (e == "16UC3") return 6;
    return 0;
}

void Image::checkLayout(const std::string &where) const {
    const int bpp = bytesPerPixel(encoding);
    if (bpp == 0)
        throw Error(where + ": encoding '" + encoding.substr(0, 40) +
                    "' is not one Binocle reads; expected mono8, mono16, rgb8, bgr8, bayer_*8, bayer_*16 or 32FC1");
    if (width == 0 || height == 0) throw Error(where + ": image of " + std::to_string(width) + "x" + std::to_string(height) + " pixels");
    if (uint64_t{step} < uint64_t{width} * static_cast<uint64_t>(bpp))
        throw Error(where + ": step " + std::to_string(step) + " is less than width " + std::to_string(width) + " x " +
                    std::to_string(bpp) + " bytes per pixel of " + encoding);
    if (uint64_t{step} * height != size)
        throw Error(where + ": data holds " + std::to_string(size) + " bytes but step x height = " + std::to_string(step) +
                    " x " + std::to_string(height) + " = " + std::to_string(uint64_t{step} * height));
}

// ---- Stereo calibration <-> CameraInfo -----------------------------------------------------

std::array<CameraInfo, 2> cameraInfos(const StereoCameraModel &m) {
    std::array<CameraInfo, 2> out;
    for (int side = 0; side < 2; ++side) {
        CameraInfo &c = out[side];
        c.width = m.width;
        c.height = m.height;
        c.distortion_model = "plumb_bob";
        c.d = side == 0 ? m.D1 : m.D2;
        c.d.resize(5, 0.0); // plumb_bob: k1 k2 t1 t2 k3
        c.k = side == 0 ? m.M1 : m.M2;
        c.r = side == 0 ? m.R1 : m.R2;
        c.p = side == 0 ? m.P1 : m.P2;
        c.p[3] /= 1000.0; // mm -> m
        c.p[7] /= 1000.0;
        c.p[11] /= 1000.0;
    }
    return out;
}

StereoCameraModel stereoModel(const CameraInfo &left, const CameraInfo &right, const std::string &where) {
    auto refuse = [&](const std::string &what) { throw Error(where + ": " + what); };
    if (left.width == 0 || left.height == 0) refuse("left camera_info has no image size (width/height 0)");
    if (left.width != right.width || left.height != right.height)
        refuse("left camera_info is " + std::to_string(left.width) + "x" + std::to_string(left.height) +
               " but right is " + std::to_string(right.width) + "x" + std::to_string(right.height));
    for (const CameraInfo *c : {&left, &right}) {
        const char *side = c == &left ? "left" : "right";
        if (!(c->k[0] > 0) || !(c->k[4] > 0)) refuse(std::string(side) + " camera_info K has no positive focal length");
        if (!(c->p[0] > 0)) refuse(std::string(side) + " camera_info P has no positive focal length");
        if (c->distortion_model != "plumb_bob" && c->distortion_model != "rational_polynomial" && !c->d.empty())
            refuse(std::string(side) + " camera_info distortion_model '" + c->distortion_model.substr(0, 40) +
                   "'; expected plumb_bob or rational_polynomial");
        for (double v : c->k) if (!std::isfinite(v)) refuse(std::string(side) + " camera_info K is not finite");
        for (double v : c->p) if (!std::isfinite(v)) refuse(std::string(side) + " camera_info P is not finite");
        for (double v : c->d) if (!std::isfinite(v)) refuse(std::string(side) + " camera_info D is not finite");
    }
    // Tx = P2(0,3) / P2(0,0), in metres: -B for a right camera right of the left one.
    const double txM = right.p[3] / right.p[0];
    if (!(std::abs(txM) > 0))
        refuse("right camera_info P(0,3) is 0: the pair has no baseline (expected P(0,3) = -fx * baseline_m)");
    StereoCameraModel m;
    m.width = left.width;
    m.height = left.height;
    m.M1 = left.k;
    m.M2 = right.k;
    m.D1 = left.d;
    m.D2 = right.d;
    auto zero = [](const std::array<double, 9> &r) {
        for (double v : r) if (v != 0) return false;
        return true;
    };
    const std::array<double, 9> I{1, 0, 0, 0, 1, 0, 0, 0, 1};
    m.R1 = zero(left.r) ? I : left.r; // an all-zero R means "identity" in many drivers
    m.R2 = zero(right.r) ? I : right.r;
    m.P1 = left.p;
    m.P2 = right.p;
    for (int i : {3, 7, 11}) {
        m.P1[i] *= 1000.0;
        m.P2[i] *= 1000.0;
    }
    // x_rect_r = x_rect_l + (Tx, 0, 0) with x_rect = R_i x_i: R = R2^T R1, T = R2^T (Tx, 0, 0).
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double s = 0;
            for (int k = 0; k < 3; ++k) s += m.R2[k * 3 + i] * m.R1[k * 3 + j];
            m.R[i * 3 + j] = s;
        }
    const double txMm = txM * 1000.0;
    for (int i = 0; i < 3; ++i) m.T[i] = m.R2[0 * 3 + i] * txMm;
    return m;
}

} // namespace binocle::ros2
