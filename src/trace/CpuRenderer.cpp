// CPU renderer; see CpuRenderer.h.
#include "src/trace/CpuRenderer.h"

#include <atomic>
#include <chrono>
#include <cmath>

#include <tbb/parallel_for.h>

#include "src/trace/DagTracer.h"
#include "src/trace/IsoSurface.h"
#include "src/trace/LabelRender.h"
#include "src/trace/Projection.h"
#include "src/trace/SliceView.h"
#include "src/trace/SurfaceHit.h"
#include "src/trace/ValueGradient.h"
#include "src/trace/VolumeRender.h"

namespace vdbdag::trace {
namespace {

// The stored ONV normal of the hit's attribute entry, when the grid has
// normals: world space (vdb_bridge computes the gradient normals through the
// grid's transform; normal grids hold world vectors). Gradient-sourced
// normals point outwards like the level-set gradient; a normal grid's
// vectors have no such orientation.
std::optional<glm::dvec3> storedNormal(const RenderGrid& grid, const RayHit& hit, bool& oriented) {
    if (!grid.normals || hit.attribute >= grid.normals->entryCount()) return std::nullopt;
    const std::array<float, 3> n = grid.normals->decode(hit.attribute);
    oriented = grid.normals->report.source == attributes::NormalReport::Source::Gradient;
    return glm::dvec3(n[0], n[1], n[2]);
}

} // namespace

Image renderCpu(const RenderGrid& grid, const Camera& camera, const RenderOptions& options, RenderStats* stats) {
    const auto start = std::chrono::steady_clock::now();
    if (grid.mip || grid.labels || grid.iso || grid.volume || grid.slice) {
        Image image;
        std::optional<std::pair<double, double>> window;
        std::optional<double> iso;
        if (grid.mip) {
            Projection p = renderMip(grid, camera, options.window);
            image = std::move(p.image);
            window = std::pair{p.low, p.high};
        } else if (grid.slice) {
            Projection p = renderSlice(grid, camera, options.slice, options.window);
            image = std::move(p.image);
            window = std::pair{p.low, p.high};
        } else if (grid.volume) {
            const TransferFunction tf = chosenTransfer(grid, options);
            image = renderVolume(grid, camera, options, tf);
            window = std::pair{tf.low, tf.high};
        } else if (grid.iso) {
            iso = chosenIso(grid, options);
            image = renderIso(grid, camera, options, *iso);
        } else {
            image = renderLabels(grid, camera, options);
        }
        if (stats) {
            stats->window = window;
            stats->iso = iso;
            stats->primaryRays = uint64_t(camera.width) * uint64_t(camera.height);
            stats->secondaryRays = 0;
            stats->milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        }
        return image;
    }
    const GridFrame frame(grid.indexToWorld);
    TraceOptions traceOptions;
    if (options.lodPixels > 0) traceOptions.lodScale = options.lodPixels * camera.pixelAngle() / frame.voxelSize();
    const DagTracer tracer(*grid.dag, traceOptions);
    const DagTracer shadowTracer(*grid.dag);
    const glm::dvec3 light = defaultLight(camera.eye, camera.target, camera.up);
    const Ray lightRay = frame.toCellRay(glm::dvec3(0), light);  // its direction is the light's, in cell space

    Image image;
    image.resize(camera.width, camera.height);
    std::atomic<uint64_t> secondary{0};
    tbb::parallel_for(tbb::blocked_range<int>(0, camera.height, 4), [&](const tbb::blocked_range<int>& rows) {
        uint64_t localSecondary = 0;
        for (int py = rows.begin(); py != rows.end(); ++py)
            for (int px = 0; px < camera.width; ++px) {
                const size_t pixel = size_t(py) * camera.width + px;
                glm::dvec3 eye, dir;
                camera.pixelRay(px, py, eye, dir);
                const Ray ray = frame.toCellRay(eye, dir);
                glm::dvec3 colour = options.background;
                if (grid.fog) {
                    double transmittance = 1, firstHit = -1;
                    glm::dvec3 sum(0);
                    const double scale = options.densityScale / (grid.valueMax * frame.voxelSize());
                    tracer.forEachSegment(ray, [&](const RayHit& box, double tLeave) {
                        if (firstHit < 0) firstHit = box.t;
                        const double density = std::max(0.0, valueAsDoubles(grid, box.attribute)[0]);
                        const double alpha = 1 - std::exp(-scale * density * (tLeave - box.t));
                        sum += transmittance * alpha * kFogEmission;
                        transmittance *= 1 - alpha;
                        return transmittance < 1e-3;
                    });
                    colour = sum + transmittance * options.background;
                    image.alpha[pixel] = float(1 - transmittance);
                    if (firstHit >= 0) image.depth[pixel] = float(firstHit);
                } else {
                    const RayHit hit = firstSurfaceHit(grid, tracer, ray, 0);
                    if (hit.hit) {
                        glm::dvec3 normal;
                        std::optional<glm::dvec3> surfaceNormal;  // a level set's gradient (index space)
                        bool oriented = false;  // outward already: not flipped towards the viewer
                        if (const std::optional<glm::dvec3> stored = storedNormal(grid, hit, oriented)) {
                            normal = *stored;  // world space already
                        } else if (const std::optional<glm::dvec3> gradient =
                                       grid.levelSet && hit.lodLevel == 0 ? valueGradient(grid, tracer, hit.voxel, valueAsDoubles(grid, hit.attribute)[0]) : std::nullopt) {
                            normal = frame.normalToWorld(*gradient);
                            surfaceNormal = *gradient;
                            oriented = true;
                        } else if (hit.faceAxis >= 0) {
                            glm::dvec3 n(0);
                            n[hit.faceAxis] = hit.faceSign;
                            normal = frame.normalToWorld(n);
                        } else {
                            normal = -dir;
                        }
                        if (glm::dot(normal, dir) > 0 && !oriented) normal = -normal;
                        double lambert = std::max(0.0, glm::dot(normal, light));
                        if (options.shadows && lambert > 0 && hit.faceAxis >= 0) {
                            // From the hit point, exactly on the entry face, towards the light.
                            Ray shadow;
                            for (int a = 0; a < 3; ++a) {
                                shadow.origin[a] = ray.origin[a] + hit.t * ray.direction[a];
                                shadow.direction[a] = lightRay.direction[a];
                            }
                            const int f = hit.faceAxis;
                            shadow.origin[f] = double(hit.faceSign < 0 ? hit.voxel[f] : hit.voxel[f] + 1);
                            if (surfaceNormal) {
                                // A level set: start off the surface, kShadowNormalOffset
                                // voxels along its gradient, so the staircase of the
                                // narrow band does not shadow its own smooth surface.
                                const glm::dvec3 n = *surfaceNormal / std::sqrt(glm::dot(*surfaceNormal, *surfaceNormal));  // as trace.comp
                                for (int a = 0; a < 3; ++a) shadow.origin[a] = shadow.origin[a] + kShadowNormalOffset * n[a];
                                ++localSecondary;
                                if (firstSurfaceHit(grid, shadowTracer, shadow, kShadowBias * frame.voxelSize()).hit) lambert = 0;
                            } else if ((shadow.direction[f] > 0) == (hit.faceSign > 0) && shadow.direction[f] != 0) {
                                ++localSecondary;
                                if (firstSurfaceHit(grid, shadowTracer, shadow, grid.levelSet ? kShadowBias * frame.voxelSize() : 0).hit) lambert = 0;
                            }  // else the light leaves through another face: no shadow test
                        }
                        colour = baseColour(grid, hit.attribute) * (kAmbient + (1 - kAmbient) * lambert);
                        image.alpha[pixel] = 1;
                        image.depth[pixel] = float(hit.t);
                        for (int a = 0; a < 3; ++a) image.normal[3 * pixel + a] = float(normal[a]);
                    }
                }
                for (int a = 0; a < 3; ++a) image.rgb[3 * pixel + a] = float(colour[a]);
            }
        secondary += localSecondary;
    });
    if (stats) {
        stats->primaryRays = uint64_t(camera.width) * uint64_t(camera.height);
        stats->secondaryRays = secondary;
        stats->milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    }
    return image;
}

} // namespace vdbdag::trace
