// The Vulkan compute backend (gpu/) on a real device (lavapipe here): a test
// shader gathers 64- and 16-bit words at random and boundary offsets of a
// 300 MB array — more than twice lavapipe's 128 MiB per-binding limit —
// through buffer device addresses, in one chunk and split over 64 MiB chunks
// uploaded through staging; results are compared with the CPU array itself.
// Also: specialisation constants reach the shader, dispatches beyond 65535
// workgroups, staged upload/download, validation-layer cleanliness, and the
// one-line errors for a missing device index, an oversized buffer and a
// missing Vulkan driver (in a child process: the loader caches its state).
// Every test skips cleanly when no Vulkan device exists.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <set>

#include <nlohmann/json.hpp>

#include "tests/unit/BuildPaths.h"
#include "gpu/ComputePipeline.h"
#include "gpu/DeviceArray.h"
#include "gpu/DeviceBuffer.h"
#include "gpu/EmbeddedShaders.h"
#include "gpu/VulkanContext.h"
#include "src/util/Error.h"
#include "tests/unit/CliRunner.h"

using namespace vdbdag;
using namespace vdbdag::gpu;

namespace {

// Null when the machine has no Vulkan device (the test then skips).
std::unique_ptr<VulkanContext> makeContext(ContextOptions options = {}) {
    try {
        return std::make_unique<VulkanContext>(options);
    } catch (const Error& e) {
        const std::string m = e.what();
        if (m.starts_with("no Vulkan device found") || m.starts_with("no usable Vulkan device")) return nullptr;
        throw;
    }
}

#define VULKAN_CONTEXT_OR_SKIP(var, ...)                                      \
    auto var = makeContext(__VA_ARGS__);                                      \
    if (!var) GTEST_SKIP() << "no Vulkan device on this machine";

// The selftest_gather.comp push-constant block (std430).
struct GatherPush {
    DeviceArrayRef source;
    uint64_t indices, out64, out16;
    uint32_t itemCount, pad;
};
static_assert(sizeof(GatherPush) == 56);

// 300 MB of random bytes, shared by the large tests (made once).
const std::vector<uint8_t>& bigArray() {
    static const std::vector<uint8_t> bytes = [] {
        std::vector<uint8_t> b(300'000'000);
        std::mt19937_64 rng(42);
        for (size_t i = 0; i + 8 <= b.size(); i += 8) {
            const uint64_t v = rng();
            std::memcpy(&b[i], &v, 8);
        }
        return b;
    }();
    return bytes;
}

// Element indices {index64, index16} per item: random ones plus those at and
// around every `boundary` multiple (bytes) and the ends of the array.
std::vector<uint64_t> gatherIndices(uint64_t bytes, uint64_t boundary, size_t randomCount) {
    const uint64_t n64 = bytes / 8, n16 = bytes / 2;
    std::vector<uint64_t> idx;
    auto add = [&](uint64_t i64, uint64_t i16) { idx.push_back(std::min(i64, n64 - 1)); idx.push_back(std::min(i16, n16 - 1)); };
    for (uint64_t b = boundary; b < bytes; b += boundary)
        for (int d = -2; d <= 2; ++d) add(b / 8 + d, b / 2 + d);
    add(0, 0);
    add(n64 - 1, n16 - 1);
    std::mt19937_64 rng(7);
    for (size_t k = 0; k < randomCount; ++k) add(rng() % n64, rng() % n16);
    return idx;
}

// Runs selftest_gather over `indices` and compares every result with the CPU array.
void gatherAndCompare(VulkanContext& ctx, const DeviceArray& array, std::span<const uint8_t> cpu, const std::vector<uint64_t>& indices,
                      uint32_t workgroupSize = 64) {
    const size_t items = indices.size() / 2;
    DeviceBuffer idx(ctx, indices.size() * 8, MemoryKind::DeviceLocal, "indices");
    idx.upload({reinterpret_cast<const uint8_t*>(indices.data()), indices.size() * 8});
    DeviceBuffer out64(ctx, items * 8, MemoryKind::HostVisible, "out64");
    DeviceBuffer out16(ctx, items * 4, MemoryKind::HostVisible, "out16");
    out16.fill(0xFFFFFFFFu);
    ComputePipeline pipeline(ctx, embeddedShader("selftest_gather"), SpecConstants{}, sizeof(GatherPush), workgroupSize, "selftest_gather");
    const GatherPush push{array.ref(), idx.address(), out64.address(), out16.address(), static_cast<uint32_t>(items), 0};
    const DispatchTiming t = pipeline.dispatch(items, push);
    EXPECT_GT(t.hostMs, 0.0);
    if (ctx.deviceInfo().timestamps) {
        EXPECT_TRUE(t.deviceTimed);
        EXPECT_GT(t.deviceMs, 0.0);
        EXPECT_LE(t.deviceMs, t.hostMs * 1.01 + 0.1);
    }
    std::vector<uint64_t> got64(items);
    std::vector<uint32_t> got16(items);
    out64.download({reinterpret_cast<uint8_t*>(got64.data()), items * 8});
    out16.download({reinterpret_cast<uint8_t*>(got16.data()), items * 4});
    size_t bad = 0;
    for (size_t i = 0; i < items && bad < 10; ++i) {
        uint64_t want64 = 0;
        uint16_t want16 = 0;
        std::memcpy(&want64, &cpu[indices[2 * i] * 8], 8);
        std::memcpy(&want16, &cpu[indices[2 * i + 1] * 2], 2);
        if (got64[i] != want64 || got16[i] != want16) {
            ++bad;
            ADD_FAILURE() << "item " << i << ": u64 index " << indices[2 * i] << " got " << got64[i] << " want " << want64
                          << "; u16 index " << indices[2 * i + 1] << " got " << got16[i] << " want " << want16;
        }
    }
    EXPECT_EQ(bad, 0u);
}

using vdbdag::testing::CommandResult;
using vdbdag::testing::runShell;

} // namespace

TEST(VulkanBackend, GathersAcrossA300MBArrayInOneChunk) {
    VULKAN_CONTEXT_OR_SKIP(ctx);
    const auto& cpu = bigArray();
    const DeviceArray array(*ctx, cpu, "300 MB test array");
    ASSERT_EQ(array.chunkCount(), 1u);
    // Beyond what one storage-buffer binding could see: the point of device addresses.
    EXPECT_GT(cpu.size(), ctx->deviceInfo().maxStorageBufferRange);
    gatherAndCompare(*ctx, array, cpu, gatherIndices(cpu.size(), 128ull << 20, 1 << 20));
}

TEST(VulkanBackend, GathersAcrossA300MBArraySplitIntoStagedChunks) {
    VULKAN_CONTEXT_OR_SKIP(ctx);
    const auto& cpu = bigArray();
    DeviceArrayOptions options;
    options.chunkShift = 26;  // 64 MiB chunks -> 5 buffers and a chunk table
    options.kind = MemoryKind::DeviceLocalStaged;
    const DeviceArray array(*ctx, cpu, "300 MB test array", options);
    ASSERT_EQ(array.chunkCount(), 5u);
    EXPECT_EQ(array.ref().chunkShift, 26u);
    for (uint32_t c = 0; c < 5; ++c) EXPECT_FALSE(array.chunk(c).isMapped());
    gatherAndCompare(*ctx, array, cpu, gatherIndices(cpu.size(), 64ull << 20, 1 << 18));
}

TEST(VulkanBackend, DispatchBeyond65535WorkgroupsUsesATwoDimensionalGrid) {
    VULKAN_CONTEXT_OR_SKIP(ctx);
    std::vector<uint8_t> cpu(1 << 20);
    std::mt19937 rng(5);
    for (auto& b : cpu) b = static_cast<uint8_t>(rng());
    const DeviceArray array(*ctx, cpu, "1 MiB array");
    // Workgroups of 1: ~200k items need more than 65535 groups in x.
    gatherAndCompare(*ctx, array, cpu, gatherIndices(cpu.size(), 1 << 16, 200003 - 34), 1);
}

TEST(VulkanBackend, SpecialisationConstantsSwitchCodeOff) {
    VULKAN_CONTEXT_OR_SKIP(ctx);
    std::vector<uint8_t> cpu(4096);
    for (size_t i = 0; i < cpu.size(); ++i) cpu[i] = static_cast<uint8_t>(i * 7 + 1);
    const DeviceArray array(*ctx, cpu, "small array");
    const std::vector<uint64_t> indices{0, 0, 511, 2047, 100, 5};
    DeviceBuffer idx(*ctx, indices.size() * 8, MemoryKind::HostVisible, "indices");
    idx.upload({reinterpret_cast<const uint8_t*>(indices.data()), indices.size() * 8});
    DeviceBuffer out64(*ctx, 3 * 8, MemoryKind::HostVisible, "out64");
    DeviceBuffer out16(*ctx, 3 * 4, MemoryKind::HostVisible, "out16");
    out64.fill(0xABABABABu);
    out16.fill(0xFFFFFFFFu);
    // READ_U16 (constant 2) off: out16 keeps its fill, out64 is written.
    ComputePipeline pipeline(*ctx, embeddedShader("selftest_gather"), SpecConstants{}.setBool(2, false), sizeof(GatherPush), 32);
    pipeline.dispatch(3, GatherPush{array.ref(), idx.address(), out64.address(), out16.address(), 3, 0});
    const auto* got64 = static_cast<const uint64_t*>(out64.mappedData());
    const auto* got16 = static_cast<const uint32_t*>(out16.mappedData());
    for (int i = 0; i < 3; ++i) {
        uint64_t want = 0;
        std::memcpy(&want, &cpu[indices[2 * i] * 8], 8);
        EXPECT_EQ(got64[i], want) << i;
        EXPECT_EQ(got16[i], 0xFFFFFFFFu) << i;
    }
}

TEST(VulkanBackend, StagedUploadAndDownloadRoundTrip) {
    VULKAN_CONTEXT_OR_SKIP(ctx);
    // 70 MiB + 3 bytes: more than one 64 MiB staging slice, odd length.
    std::vector<uint8_t> bytes((70u << 20) + 3);
    std::mt19937 rng(9);
    for (auto& b : bytes) b = static_cast<uint8_t>(rng());
    DeviceBuffer buffer(*ctx, bytes.size() + 100, MemoryKind::DeviceLocalStaged, "staged");
    EXPECT_FALSE(buffer.isMapped());
    buffer.upload(bytes, 37);
    std::vector<uint8_t> back(bytes.size());
    buffer.download(back, 37);
    EXPECT_TRUE(back == bytes);
    std::vector<uint8_t> head(37, 0xEE);
    buffer.download(head, 0);  // zero-filled at creation
    EXPECT_EQ(std::count(head.begin(), head.end(), 0), 37);
    EXPECT_THROW(buffer.download(head, buffer.size() - 10), Error);
}

TEST(VulkanBackend, ValidationLayerReportsNoErrors) {
    ContextOptions options;
    options.validation = true;
    std::unique_ptr<VulkanContext> ctx;
    try {
        ctx = makeContext(options);
    } catch (const Error& e) {
        if (std::string(e.what()).find("validation layer is missing") != std::string::npos) GTEST_SKIP() << e.what();
        throw;
    }
    if (!ctx) GTEST_SKIP() << "no Vulkan device on this machine";
    ASSERT_TRUE(ctx->validationEnabled());
    std::vector<uint8_t> cpu(1 << 16);
    for (size_t i = 0; i < cpu.size(); ++i) cpu[i] = static_cast<uint8_t>(i ^ (i >> 8));
    {
        DeviceArrayOptions chunked;
        chunked.chunkShift = 12;
        chunked.kind = MemoryKind::DeviceLocalStaged;
        const DeviceArray array(*ctx, cpu, "validated array", chunked);
        ASSERT_EQ(array.chunkCount(), 16u);
        gatherAndCompare(*ctx, array, cpu, gatherIndices(cpu.size(), 4096, 5000));
    }
    EXPECT_EQ(ctx->validationErrorCount(), 0u);
}

TEST(VulkanBackend, ImpossibleDeviceIndexGivesAOneLineError) {
    VULKAN_CONTEXT_OR_SKIP(probe);
    const size_t count = probe->allDevices().size();
    ContextOptions options;
    options.deviceIndex = static_cast<uint32_t>(count + 5);
    try {
        VulkanContext ctx(options);
        FAIL() << "device " << count + 5 << " accepted";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("Vulkan device " + std::to_string(count + 5) + " does not exist"), std::string::npos) << m;
        EXPECT_NE(m.find(probe->deviceInfo().name), std::string::npos) << m;  // lists what exists
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
}

TEST(VulkanBackend, DevicesCommandOpensTheRequestedDeviceOrFailsInOneLine) {
    VULKAN_CONTEXT_OR_SKIP(probe);
    const uint32_t index = probe->deviceInfo().index;
    const CommandResult ok = runShell(std::string(VDBDAG_BINARY) + " devices --json --device " + std::to_string(index));
    ASSERT_EQ(ok.exitCode, 0) << ok.err;
    EXPECT_EQ(nlohmann::json::parse(ok.out)["selected"], index);
    const size_t missing = probe->allDevices().size() + 3;
    const CommandResult bad = runShell(std::string(VDBDAG_BINARY) + " devices --device " + std::to_string(missing));
    EXPECT_EQ(bad.exitCode, 1);
    EXPECT_TRUE(bad.out.empty()) << bad.out;
    EXPECT_TRUE(bad.err.starts_with("vdbdag: Vulkan device " + std::to_string(missing) + " does not exist")) << bad.err;
    EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
}

TEST(VulkanBackend, OversizedBufferAndUnknownShaderGiveClearErrors) {
    VULKAN_CONTEXT_OR_SKIP(ctx);
    const uint64_t tooBig = ctx->deviceInfo().maxMemoryAllocationSize + 1;
    try {
        DeviceBuffer b(*ctx, tooBig, MemoryKind::DeviceLocal, "huge buffer");
        FAIL() << "a buffer over the allocation limit was accepted";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_TRUE(m.starts_with("huge buffer: ")) << m;
        EXPECT_NE(m.find("per-allocation limit"), std::string::npos) << m;
    }
    try {
        embeddedShader("no_such_shader");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("selftest_gather"), std::string::npos) << e.what();
    }
}

TEST(VulkanBackend, MissingDriverGivesAOneLineErrorInTheCli) {
    // VK_DRIVER_FILES takes precedence over VK_ICD_FILENAMES in newer loaders: point both nowhere.
    // (Without validation: with it, the loader's own complaints are printed too.)
    const CommandResult r = runShell("env -u VK_ADD_DRIVER_FILES -u VDBDAG_VULKAN_VALIDATION VK_ICD_FILENAMES=/nonexistent/vdbdag_icd.json "
                                     "VK_DRIVER_FILES=/nonexistent/vdbdag_icd.json " + std::string(VDBDAG_BINARY) + " devices");
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_TRUE(r.err.starts_with("vdbdag: no Vulkan device found")) << r.err;
    EXPECT_NE(r.err.find("mesa-vulkan-drivers"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

TEST(VulkanBackend, DevicesCommandListsWhatVulkaninfoSees) {
    VULKAN_CONTEXT_OR_SKIP(ctx);
    const CommandResult r = runShell(std::string(VDBDAG_BINARY) + " devices --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json report = nlohmann::json::parse(r.out);
    ASSERT_EQ(report["devices"].size(), ctx->allDevices().size());
    int chosen = 0;
    for (const auto& d : report["devices"]) {
        if (d["chosen"].get<bool>()) {
            ++chosen;
            EXPECT_EQ(d["index"], report["default"]);
            EXPECT_EQ(d["name"], ctx->deviceInfo().name);
            EXPECT_EQ(d["max_storage_buffer_range"], ctx->deviceInfo().maxStorageBufferRange);
        }
    }
    EXPECT_EQ(chosen, 1);
    // Independent reference: the names vulkaninfo (vulkan-tools) reports.
    const CommandResult vi = runShell("vulkaninfo --summary");
    if (vi.exitCode != 0) GTEST_SKIP() << "vulkaninfo unavailable";
    std::set<std::string> names;
    for (size_t pos = 0; (pos = vi.out.find("deviceName", pos)) != std::string::npos; ++pos) {
        const size_t eq = vi.out.find("= ", pos), end = vi.out.find('\n', pos);
        names.insert(vi.out.substr(eq + 2, end - eq - 2));
    }
    EXPECT_EQ(names.size(), report["devices"].size());
    for (const auto& d : report["devices"]) EXPECT_TRUE(names.count(d["name"].get<std::string>())) << d["name"];
}

// `render --backend auto` takes a GPU when vulkaninfo (the independent
// reference) lists one, and the CPU tracer when every device is a software
// emulation (lavapipe); `--backend vulkan` still takes the software device.
TEST(VulkanBackend, RenderAutoUsesTheCpuTracerUnlessThereIsAGpu) {
    const CommandResult vi = runShell("vulkaninfo --summary");
    if (vi.exitCode != 0) GTEST_SKIP() << "vulkaninfo unavailable";
    bool gpu = false, any = false;
    for (size_t pos = 0; (pos = vi.out.find("deviceType", pos)) != std::string::npos; ++pos) {
        const size_t eq = vi.out.find("= ", pos), end = vi.out.find('\n', pos);
        const std::string type = vi.out.substr(eq + 2, end - eq - 2);
        any = true;
        gpu |= type.find("PHYSICAL_DEVICE_TYPE_CPU") == std::string::npos;
    }
    const std::filesystem::path dir = vdbdag::testing::testFolder("render_auto");
    const std::string ss = (dir / "torus.ssvdag").string(), png = (dir / "torus.png").string();
    ASSERT_EQ(runShell(std::string(VDBDAG_SAMPLES_TOOL) + " " + dir.string() + " >/dev/null").exitCode, 0);
    ASSERT_EQ(runShell(std::string(VDBDAG_BINARY) + " encode " + (dir / "torus_ls.vdb").string() + " -o " + ss).exitCode, 0);
    const CommandResult r = runShell(std::string(VDBDAG_BINARY) + " render " + ss + " -o " + png + " --width 32 --height 32 --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["backend"], gpu ? "vulkan" : "cpu") << vi.out;
    if (!any) return;
    const CommandResult v = runShell(std::string(VDBDAG_BINARY) + " render " + ss + " -o " + png + " -f --width 32 --height 32 --json --backend vulkan");
    ASSERT_EQ(v.exitCode, 0) << v.err;
    EXPECT_EQ(nlohmann::json::parse(v.out)["backend"], "vulkan");
}
