// What a renderer needs to know about one encoded grid: its DAG, its value
// channel, how to shade it (surface or fog, colour or scalar), its frame,
// and the bounds of its occupied cells (for the default camera). Shared by
// the CPU renderer and the Vulkan backend.
#pragma once
#include <array>
#include <memory>
#include <string>
#include <optional>

#include "src/attributes/PaletteChannel.h"
#include "src/encoding/CompactDag.h"
#include "src/format/SsvdagFile.h"
#include "src/trace/InsideBits.h"

namespace vdbdag::trace {

enum class ValueColouring {
    None,        // mask/bool grids, or no values: a plain material
    Scalar,      // float/double/int: a colour map over [valueMin, valueMax]
    Colour,      // vec3 colours: [0,1] floats, or 0..255 integers (vec3i)
    Vector,      // other vec3 grids: 0.5 + 0.5 * normalised vector
};

struct RenderGrid {
    const encoding::CompactDag* dag = nullptr;
    const attributes::PaletteChannel* values = nullptr;  // null when the grid stores none
    // The channel `values` points to when the grid had only its coded
    // windows (a grid just encoded, not read): built here, shared by copies.
    std::shared_ptr<const attributes::PaletteChannel> ownValues;
    // ONV shading normals (`encode --normals K`, Dado et al. §4.3), one per
    // attribute entry; null when the grid stores none. Preferred to the
    // level-set gradient and the face normal when present.
    const attributes::NormalChannel* normals = nullptr;
    ValueType valueType = ValueType::Mask;
    bool levelSet = false;  // grid class "level set" with float/double values: smooth gradient normals
    // Level sets with values: value <= 0 per entry (InsideBits.h), for the
    // zero-crossing test; shared so that copies stay cheap.
    std::shared_ptr<const InsideBits> inside;
    bool fog = false;       // grid class "fog volume": emission-absorption
    bool mip = false;       // --shading mip: the largest value along each ray (Projection.h)
    bool labels = false;    // --shading labels: the first labelled voxel, a colour per label (LabelRender.h)
    bool iso = false;       // --shading iso: the first crossing of a value (IsoSurface.h)
    bool volume = false;    // --shading volume: emission-absorption through a transfer function (VolumeRender.h)
    bool slice = false;     // --shading slice: one plane of voxels, grey (SliceView.h)
    int64_t labelBackground = 0;  // the grid's background value: unlabelled, as 0 is
    ValueColouring colouring = ValueColouring::None;
    double valueMin = 0, valueMax = 1;  // over the stored values (finite ones)
    std::array<double, 16> indexToWorld{};
    std::array<double, 3> cellLo{0, 0, 0}, cellHi{1, 1, 1};  // occupied cells, [lo, hi)
};

// How a grid is shown. Auto: a level set (class "level set") as its zero
// surface; a fog volume as emission-absorption, by class or, for a float
// grid of another class, by content: every stored value >= 0 and a
// background of 0 (no level-set sign), as nanovdb_convert's "unknown" fogs;
// anything else as voxel blocks coloured by value. The others force one
// (Fog needs float or double values: Error otherwise).
// Mip: the maximum intensity projection of a scalar grid (Projection.h).
// Labels: an integer grid of labels (LabelRender.h).
// Iso: the isosurface of a scalar grid at a value (IsoSurface.h).
// Volume: a scalar grid through a transfer function (VolumeRender.h).
// Slice: one plane of a scalar grid (SliceView.h).
enum class Shading { Auto, Fog, Surface, Values, Mip, Labels, Iso, Volume, Slice };
// Parses "auto"/"fog"/"surface"/"values"/"mip"/"labels"/"iso"/"volume"/"slice" (Error otherwise).
Shading parseShading(const std::string& text);

// Chooses the shading (see Shading) from the grid's class, type, name and
// values (colour grids are vec3 grids named like Cd, color, colour, rgb, or
// any vec3i grid). `grid` must outlive the result.
RenderGrid makeRenderGrid(const format::EncodedGrid& grid, Shading shading = Shading::Auto);
// What the grid is shown as: "fog", "surface" (level set), "mip", "labels", "iso", "volume", "slice" or "values".
const char* shadingOf(const RenderGrid& grid);

// A stored value as up to three doubles (scalars in [0]).
std::array<double, 3> valueAsDoubles(const RenderGrid& grid, uint64_t attribute);
// The same with a palette block hint (PaletteChannel::lookup).
std::array<double, 3> valueAsDoubles(const RenderGrid& grid, uint64_t attribute, size_t& blockHint);

} // namespace vdbdag::trace
