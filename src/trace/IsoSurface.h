// Isosurfaces of scalar grids (`render --shading iso --iso VALUE`): each
// pixel shows the first place along its ray where the value reaches VALUE
// from below - the first voxel or tile whose value is >= VALUE. Where that
// box touches the box before it on the ray, the hit lies between their
// centres at the linear interpolation of their values (a CT's skull surface
// rather than its voxel faces); else at the box's entry. It is shaded by
// the central difference gradient of the values there (pointing to lower
// values: out of the bone), lit as surfaces are. The Vulkan tracer finds the
// same crossings and shades them with shadeIso.
#pragma once
#include <optional>
#include <vector>

#include "src/trace/Camera.h"
#include "src/trace/Image.h"
#include "src/trace/Ray.h"
#include "src/trace/RenderGrid.h"
#include "src/trace/Shading.h"

namespace vdbdag::trace {

// Per pixel, row-major: the first box reaching `iso` and the interpolated
// ray parameter of the crossing (cell-space ray, as RayHit::t); no hit
// where the ray meets none.
struct IsoHit {
    RayHit box;
    double t = 0;
};
std::vector<std::optional<IsoHit>> firstCrossings(const RenderGrid& grid, const Camera& camera, double iso);

// The value shown when none is given: Otsu's threshold of the stored values
// (a sample of at most 2^20 entries), which parts air from tissue.
double automaticIso(const RenderGrid& grid);
// The value a render uses: --iso's, else automaticIso (both tracers).
double chosenIso(const RenderGrid& grid, const RenderOptions& options);

// The image of those crossings: lit by the values' gradient (else the entry face).
Image shadeIso(const RenderGrid& grid, const Camera& camera, const RenderOptions& options, const std::vector<std::optional<IsoHit>>& hits);
// `iso`: the value of the surface (chosenIso).
Image renderIso(const RenderGrid& grid, const Camera& camera, const RenderOptions& options, double iso);

} // namespace vdbdag::trace
