// A pinhole camera in world space, the default framing of a grid, and the
// map from world rays to the DAG's cell space (Ray.h).
//
// The cell-space ray keeps the world ray's parameter: a unit world direction
// w becomes w * inverse(linear part) in cell space, so t is a world distance
// for both, whatever the grid's voxel size.
#pragma once
#include <array>
#include <string>

#include <glm/glm.hpp>

#include "src/trace/Ray.h"

namespace vdbdag::trace {

struct Camera {
    glm::dvec3 eye{0, 0, 5}, target{0, 0, 0}, up{0, 1, 0};
    double fovDegrees = 35;  // vertical field of view
    int width = 512, height = 512;

    // World-space ray through the centre of pixel (px, py), py = 0 at the top;
    // the direction is unit length.
    void pixelRay(int px, int py, glm::dvec3& origin, glm::dvec3& direction) const;
    // Angle (radians) one pixel subtends at the image centre.
    double pixelAngle() const;
};

// The affine index-to-world map of a grid (OpenVDB's row-vector convention:
// world = [i j k 1] * M) and its inverse, for rays and normals.
class GridFrame {
public:
    explicit GridFrame(const std::array<double, 16>& indexToWorld);
    Ray toCellRay(const glm::dvec3& worldOrigin, const glm::dvec3& worldDirection, double tMax = 1e300) const;
    glm::dvec3 cellToWorld(const glm::dvec3& cell) const;  // cell = index + 0.5
    // An index-space normal (e.g. a face normal or a gradient) in world space, unit length.
    glm::dvec3 normalToWorld(const glm::dvec3& indexNormal) const;
    double voxelSize() const { return voxelSize_; }  // cube root of |det|: the mean voxel edge in world units

private:
    glm::dmat3 linear_, inverse_;  // column-vector form: world = linear_ * index + translation_
    glm::dvec3 translation_;
    double voxelSize_ = 1;
};

// Where the default camera looks from, in a world whose up axis is `up`
// (0 x, 1 y, 2 z). With up y, "front" looks from +z, "side" from +x, "top"
// from +y (with -z up in the image) and "iso" from front-right-above; with
// up z (scans, CAD), front is -y and side +x; with up x, front is +z and
// side +y. "back" looks from the opposite of front (models facing -z, such
// as the Stanford Armadillo).
enum class View { Iso, Front, Back, Side, Top };
struct ViewSpec {
    int up = 1;
    View view = View::Iso;
};
// Parses "x"/"y"/"z" and "iso"/"front"/"back"/"side"/"top" (Error otherwise).
int parseUpAxis(const std::string& text);
View parseView(const std::string& text);

// A camera looking at the world-space box of the index-space cell bounds
// [lo, hi) from `view`, the whole box in view.
Camera frameBounds(const GridFrame& frame, const std::array<double, 3>& cellLo, const std::array<double, 3>& cellHi, int width, int height,
                   double fovDegrees = 35, const ViewSpec& view = {});

} // namespace vdbdag::trace
