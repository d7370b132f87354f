// Pinhole camera and grid frame; see Camera.h.
#include "src/trace/Camera.h"

#include <algorithm>
#include <cmath>

#include "src/util/Error.h"

namespace vdbdag::trace {

void Camera::pixelRay(int px, int py, glm::dvec3& origin, glm::dvec3& direction) const {
    const glm::dvec3 forward = glm::normalize(target - eye);
    const glm::dvec3 right = glm::normalize(glm::cross(forward, up));
    const glm::dvec3 trueUp = glm::cross(right, forward);
    const double halfHeight = std::tan(glm::radians(fovDegrees) / 2);
    const double halfWidth = halfHeight * double(width) / double(height);
    const double u = ((px + 0.5) / width * 2 - 1) * halfWidth;
    const double v = (1 - (py + 0.5) / height * 2) * halfHeight;
    origin = eye;
    direction = glm::normalize(forward + u * right + v * trueUp);
}

double Camera::pixelAngle() const { return 2 * std::tan(glm::radians(fovDegrees) / 2) / height; }

GridFrame::GridFrame(const std::array<double, 16>& m) {
    // Row-vector M: world_j = sum_i index_i * M[i][j] + M[3][j].
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) linear_[i][j] = m[4 * i + j];  // glm: linear_[column][row]; column i = image of index axis i
    translation_ = {m[12], m[13], m[14]};
    const double det = glm::determinant(linear_);
    if (!std::isfinite(det) || std::fabs(det) < 1e-300) throw Error("the grid's transform is singular: cannot place a camera");
    inverse_ = glm::inverse(linear_);
    voxelSize_ = std::cbrt(std::fabs(det));
}

Ray GridFrame::toCellRay(const glm::dvec3& worldOrigin, const glm::dvec3& worldDirection, double tMax) const {
    const glm::dvec3 o = inverse_ * (worldOrigin - translation_) + glm::dvec3(0.5);
    const glm::dvec3 d = inverse_ * worldDirection;
    Ray ray;
    ray.origin = {o.x, o.y, o.z};
    ray.direction = {d.x, d.y, d.z};
    ray.tMax = tMax;
    return ray;
}

glm::dvec3 GridFrame::cellToWorld(const glm::dvec3& cell) const { return linear_ * (cell - glm::dvec3(0.5)) + translation_; }

glm::dvec3 GridFrame::normalToWorld(const glm::dvec3& n) const {
    const glm::dvec3 w = glm::transpose(inverse_) * n;
    const double len = glm::length(w);
    return len > 0 ? w / len : glm::dvec3(0, 0, 1);
}

int parseUpAxis(const std::string& text) {
    if (text == "x") return 0;
    if (text == "y") return 1;
    if (text == "z") return 2;
    throw Error("--up: '" + text + "' is not x, y or z");
}

View parseView(const std::string& text) {
    if (text == "iso") return View::Iso;
    if (text == "front") return View::Front;
    if (text == "back") return View::Back;
    if (text == "side") return View::Side;
    if (text == "top") return View::Top;
    throw Error("--view: '" + text + "' is not iso, front, back, side or top");
}

Camera frameBounds(const GridFrame& frame, const std::array<double, 3>& lo, const std::array<double, 3>& hi, int width, int height,
                   double fovDegrees, const ViewSpec& view) {
    glm::dvec3 wlo(1e300), whi(-1e300);
    for (int c = 0; c < 8; ++c) {
        const glm::dvec3 corner{(c & 1) ? hi[0] : lo[0], (c & 2) ? hi[1] : lo[1], (c & 4) ? hi[2] : lo[2]};
        const glm::dvec3 w = frame.cellToWorld(corner);
        wlo = glm::min(wlo, w);
        whi = glm::max(whi, w);
    }
    Camera camera;
    camera.width = width;
    camera.height = height;
    camera.fovDegrees = fovDegrees;
    camera.target = (wlo + whi) * 0.5;
    const double radius = std::max(glm::length(whi - wlo) * 0.5, 1e-9);
    const double aspect = std::min(1.0, double(width) / double(height));
    const double distance = radius / std::sin(glm::radians(fovDegrees) / 2 * aspect) * 1.02;
    // The world's up axis u, the right-hand axis r and the axis towards the
    // viewer t, for the chosen up.
    glm::dvec3 u(0), r(0), t(0);
    u[view.up] = 1;
    if (view.up == 1) { r = {1, 0, 0}; t = {0, 0, 1}; }
    else if (view.up == 2) { r = {1, 0, 0}; t = {0, -1, 0}; }
    else { r = {0, 1, 0}; t = {0, 0, 1}; }
    glm::dvec3 from = 0.45 * r + 0.35 * u + 1.0 * t;
    camera.up = u;
    switch (view.view) {
    case View::Iso: break;
    case View::Front: from = t; break;
    case View::Back: from = -t; break;
    case View::Side: from = r; break;
    case View::Top: from = u; camera.up = -t; break;
    }
    camera.eye = camera.target + distance * glm::normalize(from);
    return camera;
}

} // namespace vdbdag::trace
