// See VolumeRender.h.
#include "src/trace/VolumeRender.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "src/trace/DagTracer.h"
#include "src/trace/Projection.h"
#include "src/trace/ValueGradient.h"

namespace vdbdag::trace {

TransferFunction automaticTransfer(const RenderGrid& grid) {
    if (!grid.values || grid.values->entryCount == 0) return {};
    const auto [low, high] = storedValueWindow(grid);
    TransferFunction tf;
    tf.low = low;
    tf.high = high;
    return tf;
}

TransferFunction chosenTransfer(const RenderGrid& grid, const RenderOptions& options) {
    TransferFunction tf = options.transfer ? *options.transfer : automaticTransfer(grid);
    if (options.window && !options.transfer) tf.low = options.window->first, tf.high = options.window->second;
    return tf;
}

Image renderVolume(const RenderGrid& grid, const Camera& camera, const RenderOptions& options, const TransferFunction& tf) {
    const GridFrame frame(grid.indexToWorld);
    const DagTracer tracer(*grid.dag);
    const glm::dvec3 light = defaultLight(camera.eye, camera.target, camera.up);
    Image image;
    image.resize(camera.width, camera.height);
    tbb::parallel_for(tbb::blocked_range<int>(0, camera.height, 4), [&](const tbb::blocked_range<int>& rows) {
        size_t hint = 0;
        for (int py = rows.begin(); py != rows.end(); ++py)
            for (int px = 0; px < camera.width; ++px) {
                const size_t pixel = size_t(py) * size_t(camera.width) + size_t(px);
                glm::dvec3 eye, dir;
                camera.pixelRay(px, py, eye, dir);
                const Ray ray = frame.toCellRay(eye, dir);
                // The cell ray's parameter per voxel length along it.
                const double perVoxel = 1 / std::sqrt(ray.direction[0] * ray.direction[0] + ray.direction[1] * ray.direction[1] +
                                                      ray.direction[2] * ray.direction[2]);
                double transmittance = 1, firstHit = -1;
                glm::dvec3 sum(0);
                tracer.forEachSegment(ray, [&](const RayHit& box, double tLeave) {
                    const double v = grid.values ? valueAsDoubles(grid, box.attribute, hint)[0] : 1.0;
                    const double a = tf.opacity(v);
                    if (a <= 0) return false;
                    const double alpha = 1 - std::pow(1 - a, (tLeave - box.t) / perVoxel);
                    if (!(alpha > 0)) return false;
                    if (firstHit < 0) firstHit = box.t;
                    double lit = 1;
                    if (alpha > 0.01) {  // worth a gradient: lit as a surface facing the viewer
                        if (const std::optional<glm::dvec3> g = valueGradient(grid, tracer, box.voxel, v))
                            lit = kAmbient + (1 - kAmbient) * std::max(0.0, glm::dot(facingNormal(frame, box, dir, -*g), light));
                    }
                    sum += transmittance * alpha * lit * tf.colour(v);
                    transmittance *= 1 - alpha;
                    return transmittance < 0.02;
                });
                const glm::dvec3 colour = sum + transmittance * options.background;
                image.alpha[pixel] = float(1 - transmittance);
                if (firstHit >= 0) image.depth[pixel] = float(firstHit);
                for (int c = 0; c < 3; ++c) image.rgb[3 * pixel + size_t(c)] = float(colour[c]);
            }
    });
    return image;
}

} // namespace vdbdag::trace
