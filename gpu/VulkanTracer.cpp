// The Vulkan tracer: uploads, pipelines, dispatches; see VulkanTracer.h. The
// camera and shading constants are computed here exactly as Camera.cpp and
// CpuRenderer.cpp compute them (same glm expressions, no contraction), so
// the shader's per-pixel rays are bit-identical to the CPU's.
#include "gpu/VulkanTracer.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>

#include <fmt/core.h>

#include "gpu/ByteSpan.h"
#include "gpu/ComputePipeline.h"
#include "gpu/DeviceArray.h"
#include "gpu/DeviceBuffer.h"
#include "gpu/DevicePaletteChannel.h"
#include "gpu/EmbeddedShaders.h"
#include "gpu/VulkanContext.h"
#include "src/trace/IsoSurface.h"
#include "src/trace/VolumeRender.h"
#include "src/trace/LabelRender.h"
#include "src/trace/Projection.h"
#include "src/util/Error.h"

namespace vdbdag::gpu {
namespace {

constexpr unsigned kMaxInnerLevels = 40;  // trace_params.glsl
constexpr uint32_t kWorkgroup = 64;       // render: one 8x8 pixel tile per workgroup
constexpr size_t kRayBatch = size_t(1) << 20;

// gpu/shaders/trace_params.glsl, std430: 8-byte members first, then 4-byte ones.
struct TraceParamsGpu {
    DeviceArrayRef inner, leaves;
    PaletteChannelGpu values, normals;
    DeviceArrayRef inside;
    int64_t origin[3], boxLo[3], boxHi[3];
    uint64_t levelStart[kMaxInnerLevels];
    double lodScale, valueMin, valueMax;
    double forward[3], right[3], trueUp[3];
    double halfWidth, halfHeight;
    double eyeCell[3], inverse[9], normalMatrix[9], light[3], lightCell[3], background[3];
    double shadowBias, fogScale, iso, tfLow, tfHigh;
    uint64_t offsetWordsPacked[2];
    int64_t sliceIndex, labelBackground;
    uint32_t log2Size, rootReflection, innerLevels, maxSteps, width, height, tilesX, normalBits, normalsOriented, sliceAxis;
    uint32_t tfColourPoints, tfOpacityPoints;
};
static_assert(sizeof(TraceParamsGpu) == 1224, "must match trace_params.glsl");

struct TracePush {
    uint64_t rays, results, counter;
    uint32_t itemCount, labelCount;
};
static_assert(sizeof(TracePush) == 32);


enum class Mode : uint32_t { Hits = 0, Render = 1, Primary = 2 };

} // namespace

struct VulkanTracer::Impl {
    VulkanContext& context;
    std::vector<DeviceArray> arrays;  // inner, leaves, then the inside bits when the grid has them
    std::vector<DevicePaletteChannel> channels;  // values, then normals when the grid has them
    DeviceBuffer params;
    DeviceBuffer counter;
    TraceParamsGpu host{};
    std::map<uint32_t, ComputePipeline*> pipelines;
    // VulkanTracer::setFloatWalk: on by default on GPUs. On a CPU device
    // (lavapipe) doubles run as fast as floats, and the float walk's error
    // bounds cost more than they save (docs/measurements.md).
    bool floatWalk = true;

    // The parameters reach the shader as a uniform buffer (set 0, binding 0).
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VkDescriptorSet paramsSet = VK_NULL_HANDLE;

    Impl(VulkanContext& c) : context(c), params(c, sizeof(TraceParamsGpu), MemoryKind::HostVisible, "trace parameters"),
                             counter(c, 16, MemoryKind::HostVisible, "shadow ray counter") {
        const VkDevice device = c.device();
        floatWalk = c.deviceInfo().type != "CPU";
        setLayout = ComputePipeline::uniformBufferSetLayout(device);
        VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1};
        VkDescriptorPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
        poolInfo.maxSets = 1;
        poolInfo.poolSizeCount = 1;
        poolInfo.pPoolSizes = &size;
        if (vkCreateDescriptorPool(device, &poolInfo, nullptr, &pool) != VK_SUCCESS) {
            vkDestroyDescriptorSetLayout(device, setLayout, nullptr);
            throw Error("Vulkan tracer: vkCreateDescriptorPool failed");
        }
        VkDescriptorSetAllocateInfo allocInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
        allocInfo.descriptorPool = pool;
        allocInfo.descriptorSetCount = 1;
        allocInfo.pSetLayouts = &setLayout;
        if (vkAllocateDescriptorSets(device, &allocInfo, &paramsSet) != VK_SUCCESS) {
            vkDestroyDescriptorPool(device, pool, nullptr);
            vkDestroyDescriptorSetLayout(device, setLayout, nullptr);
            throw Error("Vulkan tracer: vkAllocateDescriptorSets failed");
        }
        VkDescriptorBufferInfo bufferInfo{params.buffer(), 0, sizeof(TraceParamsGpu)};
        VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        write.dstSet = paramsSet;
        write.dstBinding = 0;
        write.descriptorCount = 1;
        write.descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
        write.pBufferInfo = &bufferInfo;
        vkUpdateDescriptorSets(device, 1, &write, 0, nullptr);
    }
    ~Impl() {
        vkDestroyDescriptorPool(context.device(), pool, nullptr);  // frees the set
        vkDestroyDescriptorSetLayout(context.device(), setLayout, nullptr);
    }
    Impl(const Impl&) = delete;
    Impl& operator=(const Impl&) = delete;

    ComputePipeline& pipeline(const trace::RenderGrid& grid, Mode mode, bool levelSet, bool shadows) {
        // Only what this pipeline reads is specialised, so grids share
        // pipelines: first-hit rays read no values, hits need no colours.
        const bool fog = mode == Mode::Render && grid.fog;
        const bool mip = mode == Mode::Render && grid.mip;
        const bool slice = mode == Mode::Render && grid.slice;
        const bool labels = mode == Mode::Render && grid.labels;
        const bool iso = mode == Mode::Render && grid.iso;
        const bool volume = mode == Mode::Render && grid.volume;
        const uint32_t colouring = mode == Mode::Render ? uint32_t(grid.colouring) : 0u;  // hits and primary rays: no colours
        // Level-set hits test inside bits (trace_inside.glsl), not values; renders read values for gradients and colours.
        const bool readsValues = mode == Mode::Render || (levelSet && !grid.inside);
        const uint32_t valueType = grid.values && readsValues ? uint32_t(grid.valueType) : 255u;
        const bool oneChunk = arrays[0].chunkCount() == 1 && arrays[1].chunkCount() == 1;
        const bool normals = mode == Mode::Render && !fog && grid.normals;  // only surface shading reads them
        const uint32_t key = uint32_t(mode) | (levelSet ? 4u : 0u) | (fog ? 8u : 0u) | (shadows ? 16u : 0u) | (colouring << 5) | (valueType << 8) |
                             (oneChunk ? 1u << 16 : 0u) | (normals ? 1u << 17 : 0u) | (mip ? 1u << 18 : 0u) | (slice ? 1u << 19 : 0u) | (labels ? 1u << 20 : 0u) | (iso ? 1u << 21 : 0u) | (volume ? 1u << 22 : 0u) | (floatWalk ? 1u << 23 : 0u);
        auto& slot = pipelines[key];
        if (!slot) {
            // Shared by every tracer on this context: compiling costs ~1 s on lavapipe.
            std::shared_ptr<void>& shared = context.sharedObjects()[fmt::format("trace.comp/{:x}", key)];
            if (!shared) {
                SpecConstants constants;
                constants.setUint(1, uint32_t(mode));
                constants.setBool(2, levelSet);
                constants.setUint(3, valueType);
                constants.setBool(4, fog);
                constants.setUint(5, colouring);
                constants.setBool(6, shadows);
                constants.setBool(7, oneChunk);
                constants.setBool(8, normals);
                constants.setBool(9, mip);
                constants.setBool(10, slice);
                constants.setBool(11, labels);
                constants.setBool(12, iso);
                constants.setBool(13, volume);
                constants.setBool(14, floatWalk);
                shared = std::make_shared<ComputePipeline>(context, embeddedShader("trace"), constants, uint32_t(sizeof(TracePush)), kWorkgroup,
                                                           "trace.comp", true);
            }
            slot = static_cast<ComputePipeline*>(shared.get());
        }
        return *slot;
    }

    void writeParams() { std::memcpy(params.mappedData(), &host, sizeof(host)); }
};

VulkanTracer::VulkanTracer(const ContextOptions& options, const trace::RenderGrid& grid)
    : ownContext_(std::make_unique<VulkanContext>(options)), grid_(grid) {
    upload(*ownContext_, grid, 0);
}

VulkanTracer::VulkanTracer(VulkanContext& context, const trace::RenderGrid& grid, uint32_t chunkShift) : grid_(grid) {
    upload(context, grid, chunkShift);
}

void VulkanTracer::upload(VulkanContext& context, const trace::RenderGrid& grid, uint32_t chunkShift) {
    if (!grid.dag || grid.dag->empty()) throw Error("Vulkan tracer: the grid is empty: nothing to trace");
    const encoding::CompactDag& dag = *grid.dag;
    if (dag.innerLevelCount() > kMaxInnerLevels) throw Error(fmt::format("Vulkan tracer: {} inner levels (at most {})", dag.innerLevelCount(), kMaxInnerLevels));
    if (!grid.values && grid.colouring != trace::ValueColouring::None) throw Error("Vulkan tracer: colouring without values");
    impl_ = std::make_unique<Impl>(context);
    box_ = trace::occupiedBox(dag);

    DeviceArrayOptions chunks;
    chunks.chunkShift = chunkShift;
    auto& arrays = impl_->arrays;
    arrays.reserve(3);
    arrays.emplace_back(context, orZeros(bytesOf(dag.inner)), "DAG inner words", chunks);
    arrays.emplace_back(context, orZeros(bytesOf(dag.leaves)), "DAG leaves", chunks);
    if (grid.inside) arrays.emplace_back(context, orZeros(bytesOf(grid.inside->words)), "inside bits", chunks);
    // The normal channel only when the grid has one: its pipelines are the
    // only ones that read it (HAS_NORMALS); otherwise its reference stays zero.
    auto& channels = impl_->channels;
    channels.reserve(2);
    channels.emplace_back(context, grid.values, "values", chunks);
    if (grid.normals) channels.emplace_back(context, &grid.normals->codes, "ONV normals", chunks);

    TraceParamsGpu& p = impl_->host;
    p.inner = arrays[0].ref();
    p.leaves = arrays[1].ref();
    p.values = channels[0].ref();
    if (grid.inside) p.inside = arrays[2].ref();
    if (grid.normals) {
        p.normals = channels[1].ref();
        p.normalBits = grid.normals->bits;
        p.normalsOriented = grid.normals->report.source == attributes::NormalReport::Source::Gradient ? 1u : 0u;
    }
    for (int a = 0; a < 3; ++a) {
        p.origin[a] = dag.origin[a];
        p.boxLo[a] = box_.lo[a];
        p.boxHi[a] = box_.hi[a];
    }
    for (size_t i = 0; i < dag.innerLevelCount(); ++i) {
        p.levelStart[i] = dag.levelStart[i];
        p.offsetWordsPacked[i / 21] |= uint64_t(dag.offsetWords[i] & 7u) << (3 * (i % 21));
    }
    p.valueMin = grid.valueMin;
    p.valueMax = grid.valueMax;
    p.log2Size = dag.log2Size;
    p.rootReflection = dag.rootReflection;
    p.innerLevels = uint32_t(dag.innerLevelCount());
    p.maxSteps = trace::TraceOptions{}.maxSteps;
}

VulkanTracer::~VulkanTracer() {
    primaryHits_.reset();  // before the context they live on
    renderedPixels_.reset();
    impl_.reset();
}

// Hits as trace.comp writes them (6 uint64 per ray, see its header).
void VulkanTracer::unpackHits(const void* words, std::span<trace::RayHit> hits) {
    const auto* w = static_cast<const uint64_t*>(words);
    for (size_t i = 0; i < hits.size(); ++i) {
        trace::RayHit& h = hits[i];
        const uint64_t flags = w[6 * i];
        if (!(flags & 1u)) { h = trace::RayHit{}; continue; }
        h.hit = true;
        h.faceAxis = int8_t(int((flags >> 8) & 0xFF) - 1);
        h.faceSign = int8_t(int((flags >> 16) & 0xFF) - 1);
        h.lodLevel = uint8_t((flags >> 24) & 0xFF);
        h.wideSteps = uint8_t((flags >> 1) & 0x7F);
        h.steps = uint32_t(flags >> 32);
        for (int a = 0; a < 3; ++a) h.voxel[a] = int64_t(w[6 * i + 1 + a]);
        std::memcpy(&h.t, &w[6 * i + 4], 8);
        h.attribute = w[6 * i + 5];
    }
}

void VulkanTracer::setFloatWalk(bool on) { impl_->floatWalk = on; }
bool VulkanTracer::floatWalk() const { return impl_->floatWalk; }

const DeviceInfo& VulkanTracer::deviceInfo() const { return impl_->context.deviceInfo(); }

std::vector<trace::RayHit> VulkanTracer::traceHits(std::span<const trace::Ray> rays, HitKind kind, double lodScale) {
    std::vector<trace::RayHit> hits(rays.size());
    if (rays.empty()) return hits;
    Impl& impl = *impl_;
    impl.host.lodScale = lodScale;
    impl.writeParams();
    ComputePipeline& pipe = impl.pipeline(grid_, Mode::Hits, kind == HitKind::Surface && grid_.levelSet, false);
    const size_t batch = std::min(rays.size(), kRayBatch);
    DeviceBuffer rayBuffer(impl.context, batch * 64, MemoryKind::HostVisible, "rays", false);
    DeviceBuffer hitBuffer(impl.context, batch * 48, MemoryKind::HostVisible, "ray hits", false);
    lastDeviceMs_ = 0;
    for (size_t first = 0; first < rays.size(); first += batch) {
        const size_t n = std::min(batch, rays.size() - first);
        auto* r = static_cast<double*>(rayBuffer.mappedData());
        for (size_t i = 0; i < n; ++i) {
            const trace::Ray& ray = rays[first + i];
            for (int a = 0; a < 3; ++a) {
                r[8 * i + a] = ray.origin[a];
                r[8 * i + 3 + a] = ray.direction[a];
            }
            // The shader's hits mode takes tMin as it is (DagTracer::trace);
            // firstSurfaceHit on a grid that is no level set starts at 0.
            r[8 * i + 6] = kind == HitKind::Surface && !grid_.levelSet ? std::max(ray.tMin, 0.0) : ray.tMin;
            r[8 * i + 7] = ray.tMax;
        }
        TracePush push{rayBuffer.address(), hitBuffer.address(), impl.counter.address(), uint32_t(n), 0};
        lastDeviceMs_ += pipe.dispatch(n, push, impl.paramsSet).deviceMs;
        unpackHits(hitBuffer.mappedData(), std::span<trace::RayHit>(hits).subspan(first, n));
    }
    return hits;
}

void VulkanTracer::setCamera(const trace::Camera& camera, double lodPixels) {
    TraceParamsGpu& p = impl_->host;
    const trace::GridFrame frame(grid_.indexToWorld);
    // Camera::pixelRay's per-image constants, the same glm expressions.
    const glm::dvec3 forward = glm::normalize(camera.target - camera.eye);
    const glm::dvec3 right = glm::normalize(glm::cross(forward, camera.up));
    const glm::dvec3 trueUp = glm::cross(right, forward);
    const double halfHeight = std::tan(glm::radians(camera.fovDegrees) / 2);
    const double halfWidth = halfHeight * double(camera.width) / double(camera.height);
    // GridFrame's inverse linear part, as its constructor computes it.
    glm::dmat3 linear;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) linear[i][j] = grid_.indexToWorld[4 * i + j];
    const glm::dmat3 inverse = glm::inverse(linear);
    const glm::dmat3 normalMatrix = glm::transpose(inverse);
    const glm::dvec3 light = trace::defaultLight(camera.eye, camera.target, camera.up);
    const trace::Ray eyeRay = frame.toCellRay(camera.eye, forward);
    const trace::Ray lightRay = frame.toCellRay(glm::dvec3(0), light);
    for (int a = 0; a < 3; ++a) {
        p.forward[a] = forward[a];
        p.right[a] = right[a];
        p.trueUp[a] = trueUp[a];
        p.eyeCell[a] = eyeRay.origin[a];
        p.light[a] = light[a];
        p.lightCell[a] = lightRay.direction[a];
        for (int r = 0; r < 3; ++r) {
            p.inverse[3 * a + r] = inverse[a][r];
            p.normalMatrix[3 * a + r] = normalMatrix[a][r];
        }
    }
    p.halfWidth = halfWidth;
    p.halfHeight = halfHeight;
    p.lodScale = lodPixels > 0 ? lodPixels * camera.pixelAngle() / frame.voxelSize() : 0;
    p.shadowBias = trace::kShadowBias * frame.voxelSize();
    p.width = uint32_t(camera.width);
    p.height = uint32_t(camera.height);
    p.tilesX = (p.width + 7) / 8;
}

const std::vector<trace::RayHit>& VulkanTracer::tracePrimary(const trace::Camera& camera, HitKind kind, double lodPixels) {
    Impl& impl = *impl_;
    setCamera(camera, lodPixels);
    impl.writeParams();
    ComputePipeline& pipe = impl.pipeline(grid_, Mode::Primary, kind == HitKind::Surface && grid_.levelSet, false);
    const size_t pixels = size_t(camera.width) * size_t(camera.height);
    if (!primaryHits_ || primaryHits_->size() < pixels * 48)
        primaryHits_ = std::make_unique<DeviceBuffer>(impl.context, pixels * 48, MemoryKind::HostVisible, "primary ray hits", false);
    const uint64_t items = uint64_t(impl.host.tilesX) * ((impl.host.height + 7) / 8) * kWorkgroup;
    TracePush push{0, primaryHits_->address(), impl.counter.address(), uint32_t(items), 0};
    lastDeviceMs_ = pipe.dispatch(items, push, impl.paramsSet).deviceMs;
    primaryHitsHost_.resize(pixels);
    unpackHits(primaryHits_->mappedData(), primaryHitsHost_);
    return primaryHitsHost_;
}

trace::Image VulkanTracer::render(const trace::RenderGrid& grid, const trace::Camera& camera, const trace::RenderOptions& options,
                                  trace::RenderStats& stats) {
    const auto start = std::chrono::steady_clock::now();
    if (grid.dag != grid_.dag || grid.values != grid_.values || grid.normals != grid_.normals) throw Error("Vulkan tracer: render() got a different grid than the one uploaded");
    Impl& impl = *impl_;
    TraceParamsGpu& p = impl.host;
    const trace::GridFrame frame(grid.indexToWorld);
    setCamera(camera, options.lodPixels);
    for (int a = 0; a < 3; ++a) p.background[a] = options.background[a];
    p.fogScale = options.densityScale / (grid.valueMax * frame.voxelSize());
    p.sliceIndex = options.slice.index;
    p.sliceAxis = uint32_t(options.slice.axis);
    p.labelBackground = grid.labelBackground;
    const double iso = grid.iso ? trace::chosenIso(grid, options) : 0.0;
    p.iso = iso;
    const trace::TransferFunction tf = grid.volume ? trace::chosenTransfer(grid, options) : trace::TransferFunction{};
    p.tfLow = tf.low;
    p.tfHigh = tf.high;
    p.tfColourPoints = uint32_t(tf.colourPoints.size());
    p.tfOpacityPoints = uint32_t(tf.opacityPoints.size());
    const uint32_t tilesY = (p.height + 7) / 8;
    impl.writeParams();
    std::memset(impl.counter.mappedData(), 0, 16);

    ComputePipeline& pipe = impl.pipeline(grid_, Mode::Render, grid_.levelSet, options.shadows && !grid_.fog);
    const size_t pixels = size_t(camera.width) * size_t(camera.height);
    // Reused between frames, like the primary hits: 32 bytes a pixel; labels
    // a hit each (48), iso a hit and its crossing's t (56).
    if (!renderedPixels_ || renderedPixels_->size() < pixels * 56)
        renderedPixels_ = std::make_unique<DeviceBuffer>(impl.context, pixels * 56, MemoryKind::HostVisible, "rendered pixels", false);
    DeviceBuffer& out = *renderedPixels_;
    const uint64_t items = uint64_t(p.tilesX) * tilesY * kWorkgroup;
    TracePush push{0, out.address(), impl.counter.address(), uint32_t(items), 0};
    std::unique_ptr<DeviceBuffer> points;  // --tf: the transfer function's control points
    if (grid.volume && (!tf.colourPoints.empty() || !tf.opacityPoints.empty())) {
        std::vector<double> flat;
        for (const auto& c : tf.colourPoints) flat.insert(flat.end(), c.begin(), c.end());
        for (const auto& o : tf.opacityPoints) flat.insert(flat.end(), o.begin(), o.end());
        points = std::make_unique<DeviceBuffer>(impl.context, flat.size() * 8, MemoryKind::HostVisible, "transfer function", false);
        std::memcpy(points->mappedData(), flat.data(), flat.size() * 8);
        push.rays = points->address();
    }
    std::unique_ptr<DeviceBuffer> shown;  // --labels: the labels shown
    if (grid.labels && !options.labels.empty()) {
        shown = std::make_unique<DeviceBuffer>(impl.context, options.labels.size() * 8, MemoryKind::HostVisible, "labels shown", false);
        std::memcpy(shown->mappedData(), options.labels.data(), options.labels.size() * 8);
        push.rays = shown->address();
        push.labelCount = uint32_t(options.labels.size());
    }
    lastDeviceMs_ = pipe.dispatch(items, push, impl.paramsSet).deviceMs;

    uint32_t secondary = 0;
    std::memcpy(&secondary, impl.counter.mappedData(), 4);
    stats.primaryRays = pixels;
    stats.secondaryRays = secondary;
    // What the shader left per pixel, finished as the CPU renderer finishes it.
    trace::Image image;
    if (grid.iso || grid.labels) {  // hits, shaded by the CPU's shadeIso / shadeLabels
        std::vector<trace::RayHit> boxes(pixels);
        unpackHits(out.mappedData(), boxes);
        if (grid.iso) {
            const auto* ts = reinterpret_cast<const double*>(static_cast<const uint8_t*>(out.mappedData()) + 48 * pixels);  // each crossing's t
            std::vector<std::optional<trace::IsoHit>> hits(pixels);
            for (size_t i = 0; i < pixels; ++i)
                if (boxes[i].hit) hits[i] = trace::IsoHit{boxes[i], ts[i]};
            image = trace::shadeIso(grid, camera, options, hits);
            stats.iso = iso;
        } else {
            std::vector<std::optional<trace::LabelHit>> hits(pixels);
            for (size_t i = 0; i < pixels; ++i)
                if (boxes[i].hit) {
                    const double v = trace::valueAsDoubles(grid, boxes[i].attribute)[0];
                    hits[i] = trace::LabelHit{boxes[i], std::isfinite(v) ? int64_t(v) : 0};
                }
            image = trace::shadeLabels(grid, camera, options, hits);
        }
    } else if (grid.mip || grid.slice) {  // the maxima (the slice's values) through the window, as renderMip (renderSlice) does
        std::vector<double> maxima(pixels, std::numeric_limits<double>::quiet_NaN());
        const auto* u = static_cast<const uint32_t*>(out.mappedData());
        for (size_t i = 0; i < pixels; ++i)
            if (u[8 * i + 2]) maxima[i] = std::bit_cast<double>(uint64_t(u[8 * i]) | uint64_t(u[8 * i + 1]) << 32);
        const auto [low, high] = options.window ? *options.window : trace::automaticWindow(maxima);
        stats.window = std::pair{low, high};
        image = trace::windowedGrey(maxima, camera.width, camera.height, low, high, grid.mip);
    } else {  // colours, alpha, depth and normals
        if (grid.volume) stats.window = std::pair{tf.low, tf.high};
        image.resize(camera.width, camera.height);
        const auto* f = static_cast<const float*>(out.mappedData());
        for (size_t i = 0; i < pixels; ++i) {
            for (int a = 0; a < 3; ++a) {
                image.rgb[3 * i + a] = f[8 * i + a];
                image.normal[3 * i + a] = f[8 * i + 5 + a];
            }
            image.alpha[i] = f[8 * i + 3];
            image.depth[i] = f[8 * i + 4];
        }
    }
    stats.milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return image;
}

} // namespace vdbdag::gpu
