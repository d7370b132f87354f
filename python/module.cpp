// The Python module vdbdag._vdbdag (pybind11): the public reader
// (include/vdbdag/vdbdag.h) with numpy arrays in and out. The package
// python/vdbdag/__init__.py re-exports it and adds encode/decode.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <vdbdag/vdbdag.h>

#include <array>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace py = pybind11;

namespace {

// A grid with the file that owns it (a Python object may outlive the
// File object it came from).
struct PyGrid {
    std::shared_ptr<const vdbdag::File> file;
    const vdbdag::Grid* grid;
};

// numpy's dtype and components per value type.
struct Layout {
    py::dtype dtype;
    unsigned components;
};
Layout layoutOf(const std::string& type) {
    if (type == "float") return {py::dtype::of<float>(), 1};
    if (type == "double") return {py::dtype::of<double>(), 1};
    if (type == "int32") return {py::dtype::of<int32_t>(), 1};
    if (type == "int64") return {py::dtype::of<int64_t>(), 1};
    if (type == "bool" || type == "mask") return {py::dtype::of<bool>(), 1};
    if (type == "vec3s") return {py::dtype::of<float>(), 3};
    if (type == "vec3d") return {py::dtype::of<double>(), 3};
    if (type == "vec3i") return {py::dtype::of<int32_t>(), 3};
    throw vdbdag::Error("unknown value type '" + type + "'");
}

using Coords = py::array_t<int32_t, py::array::c_style | py::array::forcecast>;

void checkCoords(const Coords& ijk) {
    if (ijk.ndim() != 2 || ijk.shape(1) != 3) throw py::value_error("ijk must be an (N, 3) array of integer coordinates");
}

// Values of a grid at coordinates `ijk`, or (isActive) whether they are active.
py::array values(const PyGrid& g, const Coords& ijk) {
    checkCoords(ijk);
    const Layout layout = layoutOf(g.grid->valueType());
    const py::ssize_t n = ijk.shape(0);
    std::vector<py::ssize_t> shape{n};
    if (layout.components == 3) shape.push_back(3);
    py::array out(layout.dtype, shape);
    auto* bytes = static_cast<uint8_t*>(out.mutable_data());
    const unsigned vs = g.grid->valueSize();
    const bool mask = vs == 0;
    const auto c = ijk.unchecked<2>();
    {
        py::gil_scoped_release release;
        vdbdag::Accessor a = g.grid->accessor();
        for (py::ssize_t i = 0; i < n; ++i) {
            if (mask) bytes[i] = a.isActive(c(i, 0), c(i, 1), c(i, 2)) ? 1 : 0;
            else a.valueBytes(c(i, 0), c(i, 1), c(i, 2), bytes + size_t(i) * vs);
        }
    }
    return out;
}

py::array_t<bool> isActive(const PyGrid& g, const Coords& ijk) {
    checkCoords(ijk);
    const py::ssize_t n = ijk.shape(0);
    py::array_t<bool> out(n);
    auto* flags = out.mutable_data();
    const auto c = ijk.unchecked<2>();
    py::gil_scoped_release release;
    vdbdag::Accessor a = g.grid->accessor();
    for (py::ssize_t i = 0; i < n; ++i) flags[i] = a.isActive(c(i, 0), c(i, 1), c(i, 2));
    return out;
}

vdbdag::IndexBBox toBox(const std::array<std::array<int64_t, 3>, 2>& box, const char* what) {
    vdbdag::IndexBBox b;
    b.min = box[0];
    b.max = box[1];
    for (int a = 0; a < 3; ++a)
        if (b.max[a] < b.min[a]) throw py::value_error(std::string(what) + ": the box's maximum is below its minimum on axis " + std::to_string(a));
    return b;
}

// The values of an inclusive index box ((x0, y0, z0), (x1, y1, z1)) every
// `stride` voxels (vdbdag::Grid::sampleBox) as an array of shape (nx, ny,
// nz[, 3]): out[a, b, c] is the voxel (x0 + a stride, y0 + b stride, z0 + c
// stride). Its memory is i fastest (Fortran order), as sampleBox writes it.
py::array dense(const PyGrid& g, const std::array<std::array<int64_t, 3>, 2>& box, uint64_t stride) {
    if (stride == 0) throw py::value_error("dense: stride must be at least 1");
    const vdbdag::IndexBBox b = toBox(box, "dense");
    const std::array<uint64_t, 3> dims = vdbdag::sampleDims(b, stride);
    if (vdbdag::sampleCount(b, stride) > (uint64_t(1) << 40)) throw py::value_error("dense: the box is too large");
    const Layout layout = layoutOf(g.grid->valueType());
    const py::ssize_t row = py::ssize_t(std::max(1u, g.grid->valueSize())), item = py::ssize_t(layout.dtype.itemsize());
    std::vector<py::ssize_t> shape{py::ssize_t(dims[0]), py::ssize_t(dims[1]), py::ssize_t(dims[2])};
    std::vector<py::ssize_t> strides{row, row * shape[0], row * shape[0] * shape[1]};
    if (layout.components == 3) {
        shape.push_back(3);
        strides.push_back(item);
    }
    py::array out(layout.dtype, shape, strides);
    void* bytes = out.mutable_data();
    py::gil_scoped_release release;
    g.grid->sampleBox(b, stride, bytes);
    return out;
}

// The active voxels and tiles overlapping a box (vdbdag::Grid::forEachActive):
// (corners (N, 3) int64, log2 of each cube's edge (N,) uint8, values (N,) or
// (N, 3), None for a mask grid).
py::tuple activeVoxels(const PyGrid& g, const std::optional<std::array<std::array<int64_t, 3>, 2>>& box) {
    vdbdag::IndexBBox b;
    if (box) b = toBox(*box, "active_voxels");
    else {
        b.min = {INT64_MIN / 4, INT64_MIN / 4, INT64_MIN / 4};
        b.max = {INT64_MAX / 4, INT64_MAX / 4, INT64_MAX / 4};
    }
    const unsigned vs = g.grid->valueSize();
    std::vector<int64_t> corners;
    std::vector<uint8_t> sizes, values;
    {
        py::gil_scoped_release release;
        g.grid->forEachActive(b, [&](const std::array<int64_t, 3>& c, unsigned log2, const void* value) {
            corners.insert(corners.end(), c.begin(), c.end());
            sizes.push_back(uint8_t(log2));
            if (vs) values.insert(values.end(), static_cast<const uint8_t*>(value), static_cast<const uint8_t*>(value) + vs);
            return true;
        });
    }
    const py::ssize_t n = py::ssize_t(sizes.size());
    py::array_t<int64_t> c({n, py::ssize_t(3)});
    if (n) std::memcpy(c.mutable_data(), corners.data(), corners.size() * sizeof(int64_t));
    py::array_t<uint8_t> l(n);
    if (n) std::memcpy(l.mutable_data(), sizes.data(), sizes.size());
    if (vs == 0) return py::make_tuple(c, l, py::none());
    const Layout layout = layoutOf(g.grid->valueType());
    std::vector<py::ssize_t> shape{n};
    if (layout.components == 3) shape.push_back(3);
    py::array v(layout.dtype, shape);
    if (n) std::memcpy(v.mutable_data(), values.data(), values.size());
    return py::make_tuple(c, l, v);
}

} // namespace

PYBIND11_MODULE(_vdbdag, m) {
    m.doc() = "Reader of .ssvdag files (vdbdag's public reader library)";
    py::register_exception<vdbdag::Error>(m, "Error", PyExc_RuntimeError);
    m.attr("format_version") = vdbdag::readableFormatVersion();

    py::class_<PyGrid>(m, "Grid")
        .def_property_readonly("name", [](const PyGrid& g) { return g.grid->name(); })
        .def_property_readonly("value_type", [](const PyGrid& g) { return g.grid->valueType(); })
        .def_property_readonly("grid_class", [](const PyGrid& g) { return g.grid->gridClass(); })
        .def_property_readonly("active_voxel_count", [](const PyGrid& g) { return g.grid->activeVoxelCount(); })
        .def_property_readonly("index_bbox",
                               [](const PyGrid& g) {
                                   const vdbdag::IndexBBox b = g.grid->indexBBox();
                                   return py::make_tuple(py::make_tuple(b.min[0], b.min[1], b.min[2]), py::make_tuple(b.max[0], b.max[1], b.max[2]));
                               })
        .def_property_readonly("index_to_world",
                               [](const PyGrid& g) {
                                   const auto m4 = g.grid->indexToWorld();
                                   py::array_t<double> out({4, 4});
                                   std::memcpy(out.mutable_data(), m4.data(), sizeof m4);
                                   return out;
                               })
        .def("values", &values, py::arg("ijk"), "values at an (N, 3) array of index coordinates: (N,) or (N, 3) for vectors, exact")
        .def("is_active", &isActive, py::arg("ijk"), "whether the voxels at an (N, 3) array of index coordinates are active")
        .def("dense", &dense, py::arg("bbox"), py::arg("stride") = 1,
             "values of the inclusive box ((x0, y0, z0), (x1, y1, z1)) every `stride` voxels (a level of detail), indexed "
             "[(i-x0)/stride, (j-y0)/stride, (k-z0)/stride]")
        .def("active_voxels", &activeVoxels, py::arg("bbox") = py::none(),
             "the active voxels and tiles (overlapping the box, if given): (corners (N, 3), log2 edge (N,), values or None for a mask)")
        .def("__repr__", [](const PyGrid& g) { return "<vdbdag.Grid '" + g.grid->name() + "' " + g.grid->valueType() + ">"; });

    py::class_<vdbdag::File, std::shared_ptr<vdbdag::File>>(m, "File")
        .def_property_readonly("path", &vdbdag::File::path)
        .def_property_readonly("grids",
                               [](const std::shared_ptr<vdbdag::File>& f) {
                                   py::list grids;
                                   for (size_t i = 0; i < f->gridCount(); ++i) grids.append(PyGrid{f, &f->grid(i)});
                                   return grids;
                               })
        .def(
            "grid",
            [](const std::shared_ptr<vdbdag::File>& f, const std::string& name, std::optional<int64_t> frame) {
                return PyGrid{f, frame ? &f->grid(name, *frame) : &f->grid(name)};
            },
            py::arg("name"), py::arg("frame") = py::none(), "the first grid of that name, or the one of that name in the frame of that number")
        .def(
            "frames",
            [](const std::shared_ptr<vdbdag::File>& f) {
                py::list frames;
                for (const vdbdag::Frame& fr : f->frames()) {
                    py::list grids;
                    for (size_t i = fr.firstGrid; i < fr.firstGrid + fr.gridCount; ++i) grids.append(PyGrid{f, &f->grid(i)});
                    frames.append(py::make_tuple(fr.number, grids));
                }
                return frames;
            },
            "the frames in order, each (number, [grids]); a file of one volume is one frame numbered 0")
        .def_property_readonly("is_sequence", &vdbdag::File::isSequence)
        .def("__repr__", [](const vdbdag::File& f) { return "<vdbdag.File '" + f.path() + "'>"; });

    m.def(
        "open",
        [](const std::string& path, uint64_t maxVoxels, uint64_t maxMemory) {
            vdbdag::OpenLimits limits;
            limits.maxVoxels = maxVoxels;
            limits.maxMemory = maxMemory;
            return std::make_shared<vdbdag::File>(vdbdag::File::open(path, limits));
        },
        py::arg("path"), py::arg("max_voxels") = vdbdag::OpenLimits{}.maxVoxels, py::arg("max_memory") = 0,
        "opens a .ssvdag file (raises vdbdag.Error with a one-line message); refuses a file that would decode to more than max_voxels "
        "entries in a layer or hold more than max_memory bytes (0: three quarters of the memory the process may use)");
}
