// SPDX-License-Identifier: MIT
// The `binocle` Python module (_binocle; binocle/__init__.py re-exports it): Rig and its
// runs, experiment(), design(), plugins(), the exceptions. The same framework code as the CLI.
#include "python/arguments.hpp"
#include "python/convert.hpp"
#include "python/design_call.hpp"
#include "python/experiment_call.hpp"
#include "python/lifecycle.hpp"
#include "python/run.hpp"

#include "app/request.hpp"
#include "config/rig_config.hpp"
#include "core/log.hpp"
#include "host/install_prefix.hpp"
#include "host/setting_json.hpp"
#include "input/image_file.hpp"

#include <pybind11/stl.h>

#include <cstdlib>
#include <limits>

namespace py = pybind11;
using namespace binocle;
using namespace binocle::python;

namespace {

PyObject *g_error = nullptr, *g_usageError = nullptr, *g_pluginError = nullptr;

std::shared_ptr<const LoadedRig> loadRigFile(const std::string &file, const py::object &set) {
    auto loaded = std::make_shared<LoadedRig>();
    loaded->host = std::make_unique<PluginHost>();
    std::vector<Override> overrides;
    for (const std::string &text : setTexts(set)) overrides.push_back(Override::parse(text));
    // No scan: the rig opens only the plugins it names (as `binocle run`).
    withoutGil([&] { loaded->rig = loadRig(file, overrides, *loaded->host); });
    return loaded;
}

class Rig {
public:
    Rig(const py::object &file, const py::object &set) : rig_(loadRigFile(*pathText(file, "file"), set)) {}

    std::unique_ptr<Run> run(const py::object &frames, const py::object &out, const py::object &force, const py::object &progress,
                             const py::object &queue_depth) {
        StreamOptions options;
        options.max_frames = wholeNumber(frames, "frames", 1, std::numeric_limits<int64_t>::max(), "until the source ends").value_or(-1);
        options.out_dir = pathText(out, "out", "nothing written").value_or("");
        options.force = flag(force, "force");
        options.progress = flag(progress, "progress");
        options.depth = static_cast<size_t>(*wholeNumber(queue_depth, "queue_depth", 1));
        return std::make_unique<Run>(rig_, options);
    }

    const RigConfig &config() const { return rig_->rig; }

private:
    std::shared_ptr<const LoadedRig> rig_;
};

// What `binocle plugins` finds: the same search path and the same isolated scan.
std::unique_ptr<PluginHost> scannedHost(const py::object &load, const py::object &timeout_ms) {
    const std::vector<std::string> files = textList(load, "load");
    const auto timeout = static_cast<int32_t>(*wholeNumber(timeout_ms, "timeout_ms", 100, std::numeric_limits<int32_t>::max()));
    auto host = std::make_unique<PluginHost>();
    withoutGil([&] {
        for (const auto &p : files) host->load(p);
        host->scan(ScanMode::Isolated, timeout);
    });
    return host;
}

void translate(std::exception_ptr p) {
    try {
        if (p) std::rethrow_exception(p);
    } catch (const OverrideError &e) {
        PyErr_SetString(g_usageError, e.what());
    } catch (const app::RequestError &e) { // ArgumentError too
        PyErr_SetString(g_usageError, e.what());
    } catch (const PluginError &e) {
        PyErr_SetString(g_pluginError, e.what());
    } catch (const Error &e) {
        PyErr_SetString(g_error, e.what());
    }
}

PyObject *newException(py::module_ &m, const char *name, const char *doc, py::tuple bases) {
    const std::string qualified = std::string("binocle.") + name;
    PyObject *type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), nullptr);
    if (!type) throw py::error_already_set();
    m.add_object(name, py::handle(type));
    return type;
}

// binocle.Error and its subclasses; C++ errors become them (translate).
void defineExceptions(py::module_ &m) {
    g_error = newException(m, "Error", "An error of Binocle: a file, key, value, plugin or device, named with what was expected "
                                       "(the message of the `binocle` command for the same mistake).",
                           py::make_tuple(py::handle(PyExc_RuntimeError)));
    g_usageError = newException(m, "UsageError", "A mistake in the call: a `set` key or value, an argument (exit status 2 of the CLI).",
                                py::make_tuple(py::handle(g_error), py::handle(PyExc_ValueError)));
    g_pluginError = newException(m, "PluginError", "A plugin refused a call or misbehaved; the message names it.",
                                 py::make_tuple(py::handle(g_error)));
    py::register_exception_translator(&translate);
}

// Where the plugins lie, the versions.
void defineInstall(py::module_ &m) {
    m.def("_set_install_prefix", &setInstallPrefix, py::arg("prefix"),
          "Where the plugins (lib/binocle/plugins) and the plugin helper (libexec/binocle) lie; set by binocle/__init__.py.");
    m.def("install_prefix", &installPrefix, "The prefix the plugins and the plugin helper are found under.");
    m.attr("__version__") = BINOCLE_VERSION;
    m.attr("ABI_VERSION") = BINOCLE_ABI_VERSION;
    m.attr("API_VERSION") = BINOCLE_API_VERSION;
}

// binocle.Frame and binocle.Run: a run's frames as they finish.
void defineRun(py::module_ &m) {
    py::class_<Frame>(m, "Frame", "One finished frame of a run; the arrays are owned by the frame (valid as long as they are used).")
        .def_readonly("index", &Frame::index, "0, 1, 2 ... frames finished in this run")
        .def_readonly("sequence", &Frame::sequence, "the source's sequence number")
        .def_readonly("left", &Frame::left, "rectified left image: H x W uint8, or H x W x 3 (BGR)")
        .def_readonly("right", &Frame::right, "rectified right image, as left")
        .def_readonly("disparity", &Frame::disparity, "H x W float32 disparity in pixels; invalid pixels <= 0")
        .def_readonly("cloud", &Frame::cloud, "N x 3 float32 points in mm, in `cloud_frame` (ground after a ground transform)")
        .def_readonly("colors", &Frame::colors, "N x 3 uint8 (R, G, B) per point, or 0 x 3 without colours")
        .def_readonly("cloud_frame", &Frame::cloud_frame, "'ground' or 'camera'")
        .def_readonly("figures", &Frame::figures, "every evaluator figure of the frame: {'evaluator.metric': value}")
        .def_readonly("metrics", &Frame::metrics, "the same, nested: {evaluator: {metric: value}}")
        .def_readonly("valid_pixel_ratio", &Frame::valid_pixel_ratio, "share of pixels with a disparity")
        .def_readonly("seconds", &Frame::seconds, "processing time of the frame, all stages added")
        .def_readonly("latency_s", &Frame::latency_s, "from the grab to the writer stage")
        .def("__repr__", [](const Frame &f) {
            return "<binocle.Frame " + std::to_string(f.index) + ": " + std::to_string(f.cloud.shape(0)) + " points, valid " +
                   std::to_string(f.valid_pixel_ratio) + ">";
        });

    py::class_<Run>(m, "Run",
                    "The frames of a run, in order, as they finish; the pipeline works on its own threads meanwhile.\n"
                    "Leaving the loop early (break, an exception, Ctrl-C) or close() stops the run as SIGINT does for\n"
                    "`binocle run`: the frames in flight are finished, the summary (summary.json with out=) says\n"
                    "'interrupted'. Usable from any thread (each frame goes to one caller; close() from another\n"
                    "thread ends the iteration); ended the same way when the interpreter exits; a child forked\n"
                    "after it started cannot use it (binocle.Error).")
        .def("__iter__", [](py::object self) { return self; })
        .def("__next__", &Run::next)
        .def("close", &Run::close, "Stops the run, if still going, and waits for its end.")
        .def("__enter__", [](py::object self) { return self; })
        .def("__exit__", [](Run &r, const py::object &, const py::object &, const py::object &) { r.close(); })
        .def_property_readonly("summary", &Run::summary,
                               "The run's summary (as summary.json: status, frame_count, metrics ...) once it ended; None before.");
}

// binocle.Rig: a rig file loaded and checked, and its runs.
void defineRig(py::module_ &m) {
    py::class_<Rig>(m, "Rig",
                    "A rig file, loaded and checked as `binocle run RIG --set KEY=VALUE` does.\n\n"
                    "set: {'matcher.num_disparities': 128} or ['matcher.num_disparities=128']; values other than\n"
                    "strings are written as YAML (True -> true). A bad key or value raises binocle.UsageError with the\n"
                    "CLI's message (file:line:col, 'did you mean').")
        .def(py::init<const py::object &, const py::object &>(), py::arg("file"), py::arg("set") = py::none())
        .def("run", &Rig::run, py::arg("frames") = py::none(), py::arg("out") = py::none(), py::arg("force") = false,
             py::arg("progress") = false, py::arg("queue_depth") = 4,
             "Runs the rig's stage pipeline (that of `binocle run`) and returns the iterator of its frames.\n"
             "frames: stop after N frames (None: until the source ends); out: also write the outputs of\n"
             "`binocle run --out DIR` there; force: as --force; queue_depth: finished frames that may wait for\n"
             "the loop (the pipeline waits beyond).")
        .def_property_readonly("name", [](const Rig &r) { return r.config().name; })
        .def_property_readonly("file", [](const Rig &r) { return r.config().file; }, "absolute path of the rig file")
        .def_property_readonly("yaml", [](const Rig &r) { return r.config().resolved_yaml; }, "the rig after the set overrides")
        .def_property_readonly("source", [](const Rig &r) { return r.config().source().plugin; }, "the source plugin's name")
        .def_property_readonly("matcher", [](const Rig &r) { return r.config().matcher().plugin; }, "the matcher plugin's name")
        .def("__repr__", [](const Rig &r) { return "<binocle.Rig '" + r.config().name + "' " + r.config().file + ">"; });
}

// binocle.experiment(), design(), plugins() and the search path.
void defineFunctions(py::module_ &m) {
    m.def("experiment", &binocle::python::experiment, py::arg("file"), py::arg("set") = py::none(), py::arg("out") = py::none(),
          py::arg("tests") = py::tuple(), py::arg("force") = false, py::arg("progress") = false,
          "Runs an experiment file as `binocle experiment FILE --set KEY=VALUE --out DIR --tests ...` does and\n"
          "returns what it wrote into DIR (default out/<name>) as results.json, a dict with the rows under 'tests'\n"
          "([{'test': id, 'status': ..., column: value ...}]), plus 'out' (DIR), 'failed' and 'seconds'.");
    m.def(
        "plugins",
        [](const py::object &load, const py::object &timeout_ms) {
            const auto host = scannedHost(load, timeout_ms);
            py::list out;
            for (const auto &p : host->plugins()) out.append(toPython(pluginJson(p)));
            return out;
        },
        py::arg("load") = py::tuple(), py::arg("timeout_ms") = 5000,
        "The plugins `binocle plugins` lists: [{'name', 'kind', 'version', 'abi_version', 'api_version',\n"
        "'description', 'path', 'settings': [{'name', 'type', 'default', 'unit', 'help', 'min', 'max', ...}]}].");
    m.def(
        "refused_plugins",
        [](const py::object &load, const py::object &timeout_ms) {
            const auto host = scannedHost(load, timeout_ms);
            py::list out;
            for (const auto &r : host->refused()) out.append(py::dict(py::arg("path") = r.path, py::arg("reason") = r.reason));
            return out;
        },
        py::arg("load") = py::tuple(), py::arg("timeout_ms") = 5000,
        "The files `binocle plugins` lists as refused: [{'path', 'reason'}].");
    m.def("plugin_search_path", &PluginHost::defaultSearchPath,
          "The folders searched for plugins: $BINOCLE_PLUGIN_PATH, then <prefix>/lib/binocle/plugins.");
    defineDesign(m);
}

} // namespace

PYBIND11_MODULE(_binocle, m) {
    m.doc() = "Binocle from Python: rigs run through the framework's stage pipeline, experiments, designs and the plugin list.";
    // The CLI's limit for the image formats whose header input/image_file.cpp does not read.
    ::setenv("OPENCV_IO_MAX_IMAGE_PIXELS", std::to_string(input::kMaxImagePixels).c_str(), 0);
    // Warnings and errors as the CLI words them ("binocle: warn: ..."), on stderr.
    LogOptions log;
    log.program = "binocle";
    setupLogging(log);
    // numpy's C API, the exit hook, the fork handler (docs/python.md, "Threads, fork and exit").
    setUpLifecycle();

    defineExceptions(m);
    defineInstall(m);
    defineRun(m);
    defineRig(m);
    defineFunctions(m);
}
