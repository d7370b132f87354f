// vdbdag._codec: Python's vdbdag.encode and vdbdag.decode, run in this
// process through the library the command line calls (app/EncodeInputs.h,
// app/DecodeFile.h): no vdbdag executable is needed. Loaded on the first
// encode or decode (it links OpenVDB and GDCM; `import vdbdag` for reading
// stays light). Keyword options are the command's long options with
// underscores (abs_error=0.01 is --abs-error 0.01); an unknown one raises
// TypeError, a refused value or input vdbdag.Error with the command's
// one-line message. The GIL is released while a file is coded; warnings and
// notes come back in the report ("warnings", "notes"; in each file's report
// of a list) instead of on stderr.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/DecodeFile.h"
#include "app/EncodeInputs.h"
#include "src/format/ReadLimits.h"
#include "src/util/ByteSize.h"
#include "src/util/Error.h"
#include "src/util/Progress.h"

namespace py = pybind11;

namespace {

// JSON to Python (dicts, lists, numbers, strings, bools, None).
py::object toPython(const nlohmann::json& j) {
    switch (j.type()) {
    case nlohmann::json::value_t::object: {
        py::dict d;
        for (const auto& [key, value] : j.items()) d[py::str(key)] = toPython(value);
        return d;
    }
    case nlohmann::json::value_t::array: {
        py::list l;
        for (const auto& value : j) l.append(toPython(value));
        return l;
    }
    case nlohmann::json::value_t::string: return py::str(j.get<std::string>());
    case nlohmann::json::value_t::boolean: return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer: return py::int_(j.get<int64_t>());
    case nlohmann::json::value_t::number_unsigned: return py::int_(j.get<uint64_t>());
    case nlohmann::json::value_t::number_float: return py::float_(j.get<double>());
    default: return py::none();
    }
}

// A str, bytes or PathLike path (bytes decoded as os.fsdecode does).
std::string pathOf(const py::handle& h) { return py::module_::import("os").attr("fsdecode")(h).cast<std::string>(); }

// A str/PathLike or a list of them.
std::vector<std::string> pathsOf(const py::handle& h) {
    if (py::isinstance<py::list>(h) || py::isinstance<py::tuple>(h)) {
        std::vector<std::string> paths;
        for (const py::handle item : h) paths.push_back(pathOf(item));
        return paths;
    }
    return {pathOf(h)};
}

// A string or a list of strings (repeatable options).
std::vector<std::string> stringsOf(const py::handle& h) {
    if (py::isinstance<py::str>(h)) return {h.cast<std::string>()};
    return h.cast<std::vector<std::string>>();
}


// A whole number in [low, high]; anything else (a float, a negative
// number, a string) is refused with the option's name.
template <typename T>
T inRange(const py::handle& h, T low, T high, const char* option) {
    const std::string text = py::repr(h).cast<std::string>();
    const std::string refuse = std::string(option) + ": " + text + " is not a whole number in " + std::to_string(low) + ".." + std::to_string(high);
    if (!py::isinstance<py::int_>(h) || py::isinstance<py::bool_>(h)) throw vdbdag::Error(refuse);
    const py::int_ n = py::reinterpret_borrow<py::int_>(h);
    if (n < py::int_(low) || n > py::int_(high)) throw vdbdag::Error(refuse);
    return n.cast<T>();
}

uint64_t sizeOf(const py::handle& h, const char* option) {
    if (py::isinstance<py::str>(h)) return vdbdag::parseByteSize(h.cast<std::string>());
    const int64_t n = inRange<int64_t>(h, INT64_MIN, INT64_MAX, option);
    if (n <= 0) throw vdbdag::Error(std::string(option) + ": " + std::to_string(n) + " is not a size: give a positive number of bytes, e.g. 512M or 4G");
    return uint64_t(n);
}

double finite(const py::handle& h, const char* option) {
    const double v = h.cast<double>();
    if (!std::isfinite(v)) throw vdbdag::Error(std::string(option) + ": " + py::str(h).cast<std::string>() + " is not a finite number");
    return v;
}

using Setter = std::function<void(const py::handle&)>;

// Applies each keyword through its setter; a None value leaves the option out.
void applyOptions(const char* function, const py::kwargs& options, const std::map<std::string, Setter>& setters) {
    for (const auto& [key, value] : options) {
        const std::string name = key.cast<std::string>();
        const auto it = setters.find(name);
        if (it == setters.end()) throw py::type_error(std::string(function) + "() got an unexpected keyword argument '" + name + "'");
        if (!value.is_none()) it->second(value);
    }
}

// Warnings and notes collected while the GIL is released.
struct Messages {
    std::mutex mutex;
    std::vector<std::string> warnings, notes;
    std::function<void(const std::string&)> into(std::vector<std::string>& list) {
        return [this, &list](const std::string& text) {
            std::lock_guard lock(mutex);
            list.push_back(text);
        };
    }
};

py::object encode(const py::object& src, const py::object& dst, const py::kwargs& options) {
    vdbdag::app::EncodeInputsRequest request;
    request.inputs = pathsOf(src);
    if (!dst.is_none()) request.output = pathOf(dst);
    vdbdag::app::EncodeRequest& c = request.coding;
    vdbdag::app::DenseInputs& d = request.dense;
    const auto flag = [](bool& field) { return [&field](const py::handle& h) { field = h.cast<bool>(); }; };
    const auto colourGrids = [&c](const py::handle& h) { c.colourGrids = stringsOf(h); };
    const auto colourBits = [&c](const py::handle& h) { c.colourBits = inRange<unsigned>(h, 1, 16, "colour_bits"); };
    std::map<std::string, Setter> setters{
        {"force", flag(c.force)},
        {"grid", [&c](const py::handle& h) { c.grids = stringsOf(h); }},
        {"skip_unsupported", flag(c.skipUnsupported)},
        {"topology_only", flag(c.topologyOnly)},
        {"no_symmetry", flag(c.noSymmetry)},
        {"no_compress", flag(c.noCompress)},
        {"no_predict", flag(c.noPredict)},
        {"svdag_stats", flag(c.svdagStats)},
        {"placement_trials", [&c](const py::handle& h) { c.placementTrials = inRange<int>(h, 1, 64, "placement_trials"); }},
        {"key_every", [&c](const py::handle& h) { c.keyEvery = inRange<unsigned>(h, 1, 256, "key_every"); }},
        {"abs_error", [&c](const py::handle& h) { c.absError = finite(h, "abs_error"); }},
        {"rel_error", [&c](const py::handle& h) { c.relError = finite(h, "rel_error"); }},
        {"colour_bits", colourBits},
        {"color_bits", colourBits},
        {"colour_grid", colourGrids},
        {"color_grid", colourGrids},
        {"normals", [&c](const py::handle& h) { c.normalBits = inRange<unsigned>(h, 1, 64, "normals"); }},
        {"normal_grid", [&c](const py::handle& h) { c.normalGrid = h.cast<std::string>(); }},
        {"memory_limit", [&c](const py::handle& h) { c.memoryLimit = sizeOf(h, "memory_limit"); }},
        {"scratch", [&c](const py::handle& h) { c.scratch = pathOf(h); }},
        {"threads", [&c](const py::handle& h) { c.threads = inRange<unsigned>(h, 1, 1024, "threads"); }},
        {"dims", [&d](const py::handle& h) { d.dims = h.cast<std::vector<int64_t>>(); }},
        {"type", [&d](const py::handle& h) { d.type = h.cast<std::string>(); }},
        {"endian", [&d](const py::handle& h) { d.endian = h.cast<std::string>(); }},
        {"spacing", [&d](const py::handle& h) { d.spacing = h.cast<std::vector<double>>(); }},
        {"origin", [&d](const py::handle& h) { d.origin = h.cast<std::vector<double>>(); }},
        {"series", [&d](const py::handle& h) { d.series = py::str(h).cast<std::string>(); }},
        {"background_below", [&d](const py::handle& h) { d.below = finite(h, "background_below"); }},
        {"background_above", [&d](const py::handle& h) { d.above = finite(h, "background_above"); }},
        {"background_value", [&d](const py::handle& h) { d.backgroundValue = finite(h, "background_value"); }},
        {"volume", [&d](const py::handle& h) { d.volume = inRange<int64_t>(h, 0, INT64_MAX, "volume"); }},
        {"drop_patient_tags", flag(d.dropPatientTags)},
        {"allow_external_data", flag(d.allowExternalData)},
    };
    applyOptions("encode", options, setters);
    Messages messages;
    vdbdag::app::EncodeInputsHooks hooks;
    hooks.file.warning = messages.into(messages.warnings);
    hooks.file.note = messages.into(messages.notes);
    std::vector<std::pair<size_t, size_t>> ends;  // one file each: the messages so far as each file is written
    hooks.onFile = [&](const nlohmann::json&) {
        std::lock_guard lock(messages.mutex);
        ends.emplace_back(messages.warnings.size(), messages.notes.size());
    };
    nlohmann::json report;
    {
        py::gil_scoped_release release;
        report = vdbdag::app::encodeInputs(request, hooks).report;
    }
    const auto slice = [](const std::vector<std::string>& all, size_t begin, size_t end) {
        return std::vector<std::string>(all.begin() + long(begin), all.begin() + long(end));
    };
    if (report.is_object()) {
        report["warnings"] = messages.warnings, report["notes"] = messages.notes;
    } else {
        for (size_t i = 0; i < report.size() && i < ends.size(); ++i) {
            const auto [w0, n0] = i ? ends[i - 1] : std::pair<size_t, size_t>{0, 0};
            report[i]["warnings"] = slice(messages.warnings, w0, ends[i].first);
            report[i]["notes"] = slice(messages.notes, n0, ends[i].second);
        }
    }
    return toPython(report);
}

py::object decode(const py::object& src, const py::object& dst, const py::kwargs& options) {
    vdbdag::app::DecodeRequest request;
    request.input = pathOf(src), request.output = pathOf(dst);
    std::string frames;
    uint64_t maxMemory = 0;
    request.limits.maxVoxels = vdbdag::format::kDefaultMaxVoxels;
    const std::map<std::string, Setter> setters{
        {"force", [&](const py::handle& h) { request.force = h.cast<bool>(); }},
        {"grid", [&](const py::handle& h) { request.grid = h.cast<std::string>(); }},
        {"stored_values", [&](const py::handle& h) { request.storedValues = h.cast<bool>(); }},
        {"frames", [&](const py::handle& h) { frames = py::str(h).cast<std::string>(); }},
        {"max_voxels", [&](const py::handle& h) { request.limits.maxVoxels = inRange<uint64_t>(h, 1, UINT64_MAX, "max_voxels"); }},
        {"max_memory", [&](const py::handle& h) { maxMemory = sizeOf(h, "max_memory"); }},
    };
    applyOptions("decode", options, setters);
    request.limits.maxMemory = maxMemory ? maxMemory : vdbdag::format::defaultReadMemory();
    std::vector<std::vector<std::string>> notes;  // each output's, in the order written
    nlohmann::json report;
    {
        py::gil_scoped_release release;
        report = vdbdag::app::decodeFiles(request, frames, [&](const std::string&, const vdbdag::app::DecodeResult& r) { notes.push_back(r.notes); });
    }
    if (report.is_object()) report["notes"] = notes.empty() ? std::vector<std::string>{} : notes.front();
    else
        for (size_t i = 0; i < report.size() && i < notes.size(); ++i) report[i]["notes"] = notes[i];
    return toPython(report);
}

} // namespace

PYBIND11_MODULE(_codec, m) {
    m.doc() = "vdbdag.encode and vdbdag.decode, in this process (see vdbdag's package documentation)";
    vdbdag::setQuiet(true);  // no progress lines inside a Python program
    py::register_local_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const vdbdag::Error& e) {
            const py::object error = py::module_::import("vdbdag._vdbdag").attr("Error");
            PyErr_SetString(error.ptr(), e.what());
        }
    });
    m.def("encode", &encode, py::arg("src"), py::arg("dst") = py::none());
    m.def("decode", &decode, py::arg("src"), py::arg("dst"));
}
