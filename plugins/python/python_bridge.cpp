// SPDX-License-Identifier: MIT
// The Python bridge: a plugin that embeds CPython and serves the Python class in the
// file beside it. One build, copied as binocle_<name>.so next to binocle_<name>.py by
// binocle_add_python_plugin(); it learns <name> from its own file (dladdr), so the host
// sees an ordinary plugin of that name. Design and rules: sdk/README.md ("Plugins in
// Python"); the class's side of the rules: python_shim.py.
#include <binocle/abi/init_error.h>
#include <binocle/plugin.hpp>
#include <binocle/settings.hpp>

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <dlfcn.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <mutex>
#include <string>
#include <vector>

extern const char *const kBinoclePythonShim; // python_shim.py, generated

namespace {

using binocle::sdk::Error;

// A strong reference, dropped with the GIL held (every use is inside a Gil scope).
class Ref {
public:
    Ref() = default;
    explicit Ref(PyObject *o) : o_(o) {}
    Ref(const Ref &) = delete;
    Ref &operator=(const Ref &) = delete;
    Ref(Ref &&other) noexcept : o_(other.o_) { other.o_ = nullptr; }
    Ref &operator=(Ref &&other) noexcept {
        if (this != &other) {
            Py_XDECREF(o_);
            o_ = other.o_;
            other.o_ = nullptr;
        }
        return *this;
    }
    ~Ref() { Py_XDECREF(o_); }
    PyObject *get() const { return o_; }
    PyObject *release() { PyObject *o = o_; o_ = nullptr; return o; }
    explicit operator bool() const { return o_ != nullptr; }

private:
    PyObject *o_ = nullptr;
};

// True once the interpreter is being torn down and this thread does not hold the GIL:
// PyGILState_Ensure would then end the thread inside C++ code (pthread_exit through
// destructors) or never return. The `binocle` module ends its runs before that (its exit
// hook); this is the bridge's own guard.
bool pythonGone() {
    if (!Py_IsInitialized()) return true;
#if PY_VERSION_HEX >= 0x030D0000
    return Py_IsFinalizing() && !PyGILState_Check();
#else
    return _Py_IsFinalizing() && !PyGILState_Check();
#endif
}

// The GIL for the length of a call; the interpreter is started, or joined, once.
class Gil {
public:
    Gil() : state_(take()) {}
    ~Gil() { PyGILState_Release(state_); }
    Gil(const Gil &) = delete;
    Gil &operator=(const Gil &) = delete;

private:
    static PyGILState_STATE take() {
        if (pythonGone()) throw Error(BINOCLE_ERR_INTERNAL, "python bridge: the Python interpreter is exiting; no call into Python now");
        return PyGILState_Ensure();
    }
    PyGILState_STATE state_;
};

// Drops references with the GIL, or leaves them (the objects go with the process) once
// the interpreter is being torn down.
template <class... Refs>
void dropAll(Refs &...refs) {
    if (pythonGone()) {
        (refs.release(), ...);
        return;
    }
    Gil gil;
    ((refs = Ref()), ...);
}

// What the module declared, read once when the library is first asked for its table.
struct Module {
    std::string name, file, kind, version, description;
    std::deque<std::string> texts; // storage of the settings table's strings
    std::vector<binocle_param_desc> params;
    std::vector<std::pair<std::string, int32_t>> types;
    PyObject *shim = nullptr;  // _binocle_bridge, never released
    PyObject *declared = nullptr; // describe()'s answer for the table read from the source
    PyObject *cls = nullptr;   // the plugin's class once imported, never released
    std::mutex importing;      // the first instance imports the module
    std::string failure;       // why loading failed (then the init symbol returns NULL)
};

const char *keep(Module &m, const std::string &s) { return m.texts.emplace_back(s).c_str(); }

std::string fileOfThisLibrary() {
    Dl_info info{};
    if (!dladdr(reinterpret_cast<void *>(&fileOfThisLibrary), &info) || !info.dli_fname)
        throw Error(BINOCLE_ERR_INTERNAL, "python bridge: dladdr cannot name the bridge's own file");
    return info.dli_fname;
}

// The pending Python exception as "TypeError: message (at file.py:12 in compute)"; clears it.
std::string pythonError(PyObject *shim) {
    PyObject *type = nullptr, *value = nullptr, *trace = nullptr;
    PyErr_Fetch(&type, &value, &trace);
    if (!type) return "unknown Python error";
    PyErr_NormalizeException(&type, &value, &trace);
    if (trace && value) PyException_SetTraceback(value, trace);
    std::string text = reinterpret_cast<PyTypeObject *>(type)->tp_name;
    Ref t(type), v(value), tb(trace);
    if (shim && value) {
        Ref said(PyObject_CallMethod(shim, "explain", "O", value));
        if (said && PyUnicode_Check(said.get())) {
            if (const char *s = PyUnicode_AsUTF8(said.get())) return s;
        }
        PyErr_Clear();
    }
    if (value) {
        Ref s(PyObject_Str(value));
        if (s && PyUnicode_Check(s.get()))
            if (const char *c = PyUnicode_AsUTF8(s.get())) text += std::string(": ") + c;
        PyErr_Clear();
    }
    return text;
}

std::string textOf(PyObject *o) {
    if (!o || o == Py_None) return {};
    const char *s = PyUnicode_Check(o) ? PyUnicode_AsUTF8(o) : nullptr;
    if (!s) throw Error(BINOCLE_ERR_INTERNAL, "python bridge: expected a str from the shim");
    return s;
}

// Starts the interpreter unless the process has one (the `binocle` Python module, or a
// second Python plugin), loads the shim and reads the plugin's table from its source
// (the module itself is imported by the first instance: importModule).
void load(Module &m) {
    const std::string so = fileOfThisLibrary();
    const std::string folder = so.substr(0, so.rfind('/') + 1);
    std::string base = so.substr(folder.size());
    if (base.rfind("binocle_", 0) != 0 || base.size() < 12 || base.compare(base.size() - 3, 3, ".so") != 0)
        throw Error(BINOCLE_ERR_INTERNAL, "python bridge: its file " + so + " is not named binocle_<name>.so");
    m.name = base.substr(8, base.size() - 11);
    m.file = folder + "binocle_" + m.name + ".py";
    // This library stays loaded for the life of the process (the interpreter may hold
    // objects made here), and libpython's symbols become global, so that the extension
    // modules numpy loads (which do not link libpython) find them.
    dlopen(so.c_str(), RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
    Dl_info py{};
    if (dladdr(reinterpret_cast<void *>(&Py_IsInitialized), &py) && py.dli_fname)
        dlopen(py.dli_fname, RTLD_NOW | RTLD_NOLOAD | RTLD_GLOBAL);
    if (!Py_IsInitialized()) {
        PyConfig config;
        PyConfig_InitPythonConfig(&config);
        config.install_signal_handlers = 0; // SIGINT stays Binocle's
        config.write_bytecode = 0;          // nothing written beside installed plugins
        config.parse_argv = 0;
        // The interpreter whose libpython this is (CMake's Python3_EXECUTABLE): its
        // prefix gives the standard library and site-packages; a name alone would be
        // looked up on PATH, where another Python (pyenv, a venv) may come first.
        PyConfig_SetBytesString(&config, &config.program_name, BINOCLE_PYTHON_EXECUTABLE);
        const PyStatus status = Py_InitializeFromConfig(&config);
        PyConfig_Clear(&config);
        if (PyStatus_Exception(status))
            throw Error(BINOCLE_ERR_INTERNAL, std::string("cannot start Python: ") + (status.err_msg ? status.err_msg : "?"));
        PyEval_SaveThread(); // the GIL is taken per call from here on
    }
    Gil gil;
    Ref code(Py_CompileString(kBinoclePythonShim, "<binocle python bridge>", Py_file_input));
    Ref shim(code ? PyImport_ExecCodeModule("_binocle_bridge", code.get()) : nullptr);
    if (!shim) throw Error(BINOCLE_ERR_INTERNAL, "python bridge: its shim does not load: " + pythonError(nullptr));
    m.shim = shim.release();
    // The table from the source's syntax tree: nothing of the plugin runs before `create`.
    Ref declared(PyObject_CallMethod(m.shim, "read_table", "ss", m.file.c_str(), m.name.c_str()));
    if (!declared) throw Error(BINOCLE_ERR_INTERNAL, "cannot read " + m.file + ": " + pythonError(m.shim));
    Ref info(PyObject_CallMethod(m.shim, "describe", "Os", declared.get(), m.name.c_str()));
    if (!info) throw Error(BINOCLE_ERR_INTERNAL, m.file + ": " + pythonError(m.shim));
    m.declared = Py_NewRef(info.get());
    m.kind = textOf(PyTuple_GetItem(info.get(), 0));
    m.version = textOf(PyTuple_GetItem(info.get(), 1));
    m.description = textOf(PyTuple_GetItem(info.get(), 2));
    PyObject *settings = PyTuple_GetItem(info.get(), 3);
    for (Py_ssize_t i = 0; i < PyList_Size(settings); ++i) {
        PyObject *s = PyList_GetItem(settings, i);
        binocle_param_desc d{};
        const std::string name = textOf(PyTuple_GetItem(s, 0));
        d.name = keep(m, name);
        d.type = static_cast<int32_t>(PyLong_AsLong(PyTuple_GetItem(s, 1)));
        d.flags = static_cast<uint32_t>(PyLong_AsLong(PyTuple_GetItem(s, 2)));
        PyObject *def = PyTuple_GetItem(s, 3);
        d.default_value = def == Py_None ? nullptr : keep(m, textOf(def));
        d.min = PyFloat_AsDouble(PyTuple_GetItem(s, 4));
        d.max = PyFloat_AsDouble(PyTuple_GetItem(s, 5));
        d.multiple_of = PyLong_AsLongLong(PyTuple_GetItem(s, 6));
        PyObject *choices = PyTuple_GetItem(s, 7);
        d.choices = choices == Py_None ? nullptr : keep(m, textOf(choices));
        d.unit = keep(m, textOf(PyTuple_GetItem(s, 8)));
        d.help = keep(m, textOf(PyTuple_GetItem(s, 9)));
        m.params.push_back(d);
        m.types.emplace_back(name, d.type);
    }
    if (PyErr_Occurred()) throw Error(BINOCLE_ERR_INTERNAL, m.file + ": settings table: " + pythonError(m.shim));
}

Module &module() {
    static Module m; // in place: the table points into its strings
    static const bool loaded = [] {
        try {
            load(m);
        } catch (const std::exception &e) {
            m.failure = e.what();
        }
        return true;
    }();
    (void)loaded;
    return m;
}

int channelsOf(const binocle_image &im) {
    return im.format == BINOCLE_PIXEL_BGR8 || im.format == BINOCLE_PIXEL_RGB8 ? 3 : 1;
}

// Fills bytes Python owns from a host image, row by row as they are (a BGR8 image is
// shown to Python in RGB order by a reversed view: shim.image). The last call's bytes
// are reused when nothing in Python refers to them any more (no page faults on fresh
// memory each frame); a matcher that kept its input gets new ones.
void fill(Ref &bytes, const binocle_image &im) {
    const size_t row = static_cast<size_t>(im.width) * binocle::sdk::bytesPerPixel(im.format);
    const auto size = static_cast<Py_ssize_t>(row * im.height);
    if (!bytes || Py_REFCNT(bytes.get()) != 1 || PyByteArray_Size(bytes.get()) != size)
        bytes = Ref(PyByteArray_FromStringAndSize(nullptr, size));
    if (!bytes) return;
    auto *out = reinterpret_cast<uint8_t *>(PyByteArray_AsString(bytes.get()));
    for (int y = 0; y < im.height; ++y)
        std::memcpy(out + y * row, static_cast<const uint8_t *>(im.data) + static_cast<size_t>(y) * im.stride_bytes, row);
}

[[noreturn]] void raised(const Module &m, const char *call, binocle_result code) {
    throw Error(code, m.file + ": " + call + " raised " + pythonError(m.shim));
}

// A numpy array of a copy of a host image (GRAY8, BGR8 as RGB, RGB8, GRAY16, FLOAT32).
PyObject *arrayOf(const Module &m, const binocle_image &im) {
    const int bpp = binocle::sdk::bytesPerPixel(im.format);
    if (bpp == 0 || !im.data || im.width < 1 || im.height < 1 || im.stride_bytes < im.width * bpp) return Py_NewRef(Py_None);
    Ref bytes;
    fill(bytes, im);
    if (!bytes) return nullptr;
    const int channels = channelsOf(im);
    return PyObject_CallMethod(m.shim, "image", "Oiiiii", bytes.get(), im.height, im.width, channels, bpp / channels,
                               im.format == BINOCLE_PIXEL_BGR8);
}

// The module imported (its code runs now, in the process that makes an instance), and
// its class checked against the table the host was given.
void importModule(Module &m) {
    Ref cls(PyObject_CallMethod(m.shim, "load", "ss", m.file.c_str(), m.name.c_str()));
    if (!cls) throw Error(BINOCLE_ERR_INTERNAL, "cannot load " + m.file + ": " + pythonError(m.shim));
    Ref info(PyObject_CallMethod(m.shim, "describe", "Os", cls.get(), m.name.c_str()));
    if (!info) throw Error(BINOCLE_ERR_INTERNAL, m.file + ": " + pythonError(m.shim));
    const int same = PyObject_RichCompareBool(info.get(), m.declared, Py_EQ);
    if (same != 1) {
        PyErr_Clear();
        throw Error(BINOCLE_ERR_INTERNAL, m.file + ": the imported class's name, kind, version, description or "
                                          "settings differ from the literals of its source (set them as literals "
                                          "in the class body, not at run time)");
    }
    m.cls = cls.release();
}

// An instance of the module's class, given the settings the SDK checked against the table.
Ref makeInstance(Module &m, const binocle::sdk::CheckedParams &c) {
    std::lock_guard<std::mutex> lock(m.importing); // taken before the GIL, never while holding it
    Gil gil;
    if (!m.cls) importModule(m);
    Ref values(PyDict_New()), types(PyDict_New());
    for (const auto &[name, type] : m.types) {
        Ref v;
        switch (type) {
        case BINOCLE_PARAM_BOOL: v = Ref(PyBool_FromLong(c.boolean(name))); break;
        case BINOCLE_PARAM_INT: v = Ref(PyLong_FromLongLong(c.integer(name))); break;
        case BINOCLE_PARAM_DOUBLE: v = Ref(PyFloat_FromDouble(c.real(name))); break;
        default: v = Ref(PyUnicode_FromString(c.string(name).c_str())); break;
        }
        Ref t(PyLong_FromLong(type));
        PyDict_SetItemString(values.get(), name.c_str(), v.get());
        PyDict_SetItemString(types.get(), name.c_str(), t.get());
    }
    Ref instance(PyObject_CallMethod(m.shim, "create", "OOO", m.cls, values.get(), types.get()));
    if (!instance) raised(m, "__init__", BINOCLE_ERR_INVALID_ARGUMENT);
    return instance;
}

// Disparities that are NaN or infinite in a row (exponent bits all set), in a loop the
// compiler vectorises.
size_t nonFiniteIn(const float *row, int n) {
    size_t count = 0;
    for (int x = 0; x < n; ++x) {
        uint32_t bits;
        std::memcpy(&bits, row + x, sizeof bits);
        count += (bits & 0x7f800000u) == 0x7f800000u;
    }
    return count;
}

class PyMatcher : public binocle::sdk::Matcher {
public:
    static std::vector<binocle_param_desc> parameters() { return module().params; }

    PyMatcher(const binocle::sdk::CheckedParams &p, binocle::sdk::Host &) : m_(module()), instance_(makeInstance(m_, p)) {}

    ~PyMatcher() override { dropAll(instance_, leftBytes_, rightBytes_); }

    void compute(const binocle_image &left, const binocle_image &right, binocle_image &disparity) override {
        checkInputs(left, right, disparity);
        Gil gil;
        const int channels = channelsOf(left);
        fill(leftBytes_, left);
        fill(rightBytes_, right);
        if (!leftBytes_ || !rightBytes_) fail("compute", BINOCLE_ERR_INTERNAL);
        const int bgr = left.format == BINOCLE_PIXEL_BGR8;
        Ref l(PyObject_CallMethod(m_.shim, "image", "Oiiiii", leftBytes_.get(), left.height, left.width, channels, 1, bgr));
        Ref r(l ? PyObject_CallMethod(m_.shim, "image", "Oiiiii", rightBytes_.get(), left.height, left.width, channels, 1, bgr)
                : nullptr);
        if (!r) fail("compute", BINOCLE_ERR_INTERNAL);
        Ref result(PyObject_CallMethod(instance_.get(), "compute", "OO", l.get(), r.get()));
        if (!result) fail("compute", BINOCLE_ERR_INTERNAL);
        writeDisparity(result.get(), disparity);
    }

    std::pair<int32_t, int32_t> disparityRange() const override {
        Gil gil;
        Ref range(PyObject_CallMethod(m_.shim, "disparity_range", "O", instance_.get()));
        int lo = 0, count = 0;
        if (!range || !PyArg_ParseTuple(range.get(), "ii", &lo, &count)) fail("disparity_range", BINOCLE_ERR_INTERNAL);
        return {lo, count};
    }

private:
    [[noreturn]] void fail(const char *call, binocle_result code) const { raised(m_, call, code); }

    static void checkInputs(const binocle_image &l, const binocle_image &r, const binocle_image &d) {
        auto fmt = [](int32_t f) { return f == BINOCLE_PIXEL_GRAY8 || f == BINOCLE_PIXEL_BGR8 || f == BINOCLE_PIXEL_RGB8; };
        if (!fmt(l.format) || l.format != r.format)
            throw Error(BINOCLE_ERR_UNSUPPORTED, "compute: input format " + std::to_string(l.format) + "/" +
                                                     std::to_string(r.format) + ": expected GRAY8, BGR8 or RGB8, the same for both");
        if (l.width != r.width || l.height != r.height || d.width != l.width || d.height != l.height || l.width < 1 ||
            l.height < 1 || d.format != BINOCLE_PIXEL_FLOAT32 || !l.data || !r.data || !d.data)
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "compute: expected two images of one size and a FLOAT32 disparity of that size");
        const int bpp = binocle::sdk::bytesPerPixel(l.format);
        if (l.stride_bytes < l.width * bpp || r.stride_bytes < r.width * bpp || d.stride_bytes < d.width * 4)
            throw Error(BINOCLE_ERR_INVALID_ARGUMENT, "compute: a stride is shorter than its row");
    }

    // The result, checked: (height, width) float32 pixels (<= 0: no match) or int16
    // pixels x 16 (OpenCV's fixed point, < 0: no match); never NaN or infinite.
    void writeDisparity(PyObject *result, binocle_image &d) const {
        Py_buffer view{};
        const std::string prefix = m_.file + ": compute returned ";
        const std::string expected = "; expected a numpy array of shape (" + std::to_string(d.height) + ", " +
                                     std::to_string(d.width) + ") (the left image's), dtype float32 (pixels, <= 0 "
                                     "where no match) or int16 (pixels x 16)";
        auto named = [&] {
            Ref s(PyObject_CallMethod(m_.shim, "dtype_of", "O", result));
            std::string t = s ? textOf(s.get()) : std::string("?");
            PyErr_Clear();
            return t;
        };
        if (PyObject_GetBuffer(result, &view, PyBUF_RECORDS_RO) != 0) {
            PyErr_Clear();
            throw Error(BINOCLE_ERR_INTERNAL, prefix + "a " + named() + expected);
        }
        struct Release {
            Py_buffer *v;
            ~Release() { PyBuffer_Release(v); }
        } release{&view};
        std::string format = view.format ? view.format : "B";
        if (!format.empty() && (format[0] == '<' || format[0] == '=' || format[0] == '@')) format.erase(0, 1);
        const bool isFloat = format == "f" && view.itemsize == 4, isFixed = format == "h" && view.itemsize == 2;
        if (!isFloat && !isFixed) throw Error(BINOCLE_ERR_INTERNAL, prefix + "a " + named() + expected);
        if (view.ndim != 2 || view.shape[0] != d.height || view.shape[1] != d.width)
            throw Error(BINOCLE_ERR_INTERNAL, prefix + "a " + named() + expected);
        size_t nonFinite = 0;
        for (int y = 0; y < d.height; ++y) {
            const char *in = static_cast<const char *>(view.buf) + y * view.strides[0];
            float *out = reinterpret_cast<float *>(static_cast<char *>(d.data) + static_cast<size_t>(y) * d.stride_bytes);
            if (isFloat && view.strides[1] == 4) {
                std::memcpy(out, in, static_cast<size_t>(d.width) * 4);
                if (size_t bad = nonFiniteIn(out, d.width)) {
                    nonFinite += bad;
                    for (int x = 0; x < d.width; ++x)
                        if (!std::isfinite(out[x])) out[x] = BINOCLE_INVALID_DISPARITY;
                }
            } else if (isFloat) {
                for (int x = 0; x < d.width; ++x) {
                    float v;
                    std::memcpy(&v, in + x * view.strides[1], sizeof v);
                    if (!std::isfinite(v)) ++nonFinite, v = BINOCLE_INVALID_DISPARITY;
                    out[x] = v;
                }
            } else {
                for (int x = 0; x < d.width; ++x) {
                    int16_t v;
                    std::memcpy(&v, in + x * view.strides[1], sizeof v);
                    out[x] = v < 0 ? BINOCLE_INVALID_DISPARITY : static_cast<float>(v) / 16.0f;
                }
            }
        }
        if (nonFinite)
            throw Error(BINOCLE_ERR_INTERNAL, prefix + std::to_string(nonFinite) + " of " +
                                                  std::to_string(static_cast<size_t>(d.width) * d.height) +
                                                  " disparities not finite (NaN or infinite); write -1 where there "
                                                  "is no match (numpy.nan_to_num(d, nan=-1, posinf=-1, neginf=-1))");
    }

    Module &m_;
    Ref instance_, leftBytes_, rightBytes_;
};

// An evaluator: evaluate(frame) gets a Frame of numpy copies and returns its figures.
class PyEvaluator : public binocle::sdk::Evaluator {
public:
    static std::vector<binocle_param_desc> parameters() { return module().params; }

    PyEvaluator(const binocle::sdk::CheckedParams &p, binocle::sdk::Host &host)
        : m_(module()), host_(host), instance_(makeInstance(m_, p)) {}

    ~PyEvaluator() override { dropAll(instance_); }

    void evaluate(const binocle_eval_input &in) override {
        Gil gil;
        Ref fields(PyDict_New());
        auto put = [&](const char *key, PyObject *value) {
            if (!value) raised(m_, "evaluate", BINOCLE_ERR_INTERNAL);
            PyDict_SetItemString(fields.get(), key, value);
            Py_DECREF(value);
        };
        auto text = [](const char *s) { return s ? PyUnicode_FromString(s) : Py_NewRef(Py_None); };
        auto image = [&](const binocle_image *im) { return im ? arrayOf(m_, *im) : Py_NewRef(Py_None); };
        put("left", image(in.rectified_left));
        put("right", image(in.rectified_right));
        put("disparity", image(in.disparity));
        Ref extras(PyDict_New());
        if (const binocle_stereo_frame *f = in.frame) {
            put("sequence", PyLong_FromUnsignedLongLong(f->sequence));
            put("metadata", text(f->metadata));
            for (int32_t i = 0; i < f->extra_count && f->extras; ++i) {
                Ref a(arrayOf(m_, f->extras[i].image));
                if (!a || !f->extras[i].name) raised(m_, "evaluate", BINOCLE_ERR_INTERNAL);
                PyDict_SetItemString(extras.get(), f->extras[i].name, a.get());
            }
        }
        put("extras", extras.release());
        if (const binocle_cloud *c = in.cloud; c && c->xyz && c->count > 0) {
            const binocle_image xyz = binocle::sdk::makeImage(3, static_cast<int32_t>(c->count), BINOCLE_PIXEL_FLOAT32, c->xyz);
            put("cloud", arrayOf(m_, xyz));
        } else {
            put("cloud", Py_NewRef(Py_None));
        }
        put("calibration_yaml", text(in.calibration_yaml));
        put("rig_yaml", text(in.rig_yaml));
        put("output_dir", text(in.output_dir));
        const bool range = BINOCLE_EVAL_INPUT_HAS(in, num_disparities) && in.num_disparities > 0;
        put("disparity_range", range ? Py_BuildValue("(ii)", in.min_disparity, in.num_disparities) : Py_NewRef(Py_None));
        const bool pose = BINOCLE_EVAL_INPUT_HAS(in, inclination_deg) && in.ground_pose_known;
        put("ground_pose", pose ? Py_BuildValue("(dd)", in.camera_height_mm, in.inclination_deg) : Py_NewRef(Py_None));
        Ref frame(PyObject_CallMethod(m_.shim, "frame", "O", fields.get()));
        if (!frame) raised(m_, "evaluate", BINOCLE_ERR_INTERNAL);
        Ref result(PyObject_CallMethod(instance_.get(), "evaluate", "O", frame.get()));
        if (!result) raised(m_, "evaluate", BINOCLE_ERR_INTERNAL);
        report(result.get(), "evaluate");
    }

    void finish() override {
        Gil gil;
        if (!PyObject_HasAttrString(instance_.get(), "finish")) return;
        Ref result(PyObject_CallMethod(instance_.get(), "finish", nullptr));
        if (!result) raised(m_, "finish", BINOCLE_ERR_INTERNAL);
        report(result.get(), "finish");
    }

private:
    void report(PyObject *result, const char *call) {
        Ref list(PyObject_CallMethod(m_.shim, "figures", "O", result));
        if (!list) throw Error(BINOCLE_ERR_INTERNAL, m_.file + ": " + call + " " + pythonError(m_.shim));
        for (Py_ssize_t i = 0; i < PyList_Size(list.get()); ++i) {
            PyObject *f = PyList_GetItem(list.get(), i);
            host_.metric(textOf(PyTuple_GetItem(f, 0)), PyFloat_AsDouble(PyTuple_GetItem(f, 1)), textOf(PyTuple_GetItem(f, 2)));
        }
    }

    Module &m_;
    binocle::sdk::Host &host_;
    Ref instance_;
};

} // namespace

// The init symbol: the table of the kind the module declares, or NULL when it cannot
// load (why: binocle_plugin_init_error, which the host adds to its refusal).
extern "C" BINOCLE_PLUGIN_EXPORT const binocle_plugin_header *binocle_plugin_init(uint32_t, uint32_t) {
    try {
        Module &m = module();
        if (!m.failure.empty()) return nullptr;
        namespace d = binocle::sdk::detail;
        if (m.kind == "evaluator")
            return &d::evaluatorTable<PyEvaluator>(m.name.c_str(), m.version.c_str(), m.description.c_str())->header;
        return &d::matcherTable<PyMatcher>(m.name.c_str(), m.version.c_str(), m.description.c_str())->header;
    } catch (...) {
        return nullptr;
    }
}

// Why init returned NULL: the module's file, the line and the Python error
// ("cannot read .../binocle_x.py: SyntaxError: invalid syntax (at .../binocle_x.py:7:5)").
extern "C" BINOCLE_PLUGIN_EXPORT const char *binocle_plugin_init_error() {
    try {
        const Module &m = module();
        return m.failure.empty() ? nullptr : m.failure.c_str();
    } catch (...) {
        return nullptr;
    }
}
