// The Vulkan infrastructure: errors, handle owners, device choice, and a
// compute shader run end to end under the validation layers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "render/vulkan/Context.h"
#include "render/vulkan/Devices.h"
#include "render/vulkan/Handles.h"
#include "render/vulkan/Memory.h"
#include "render/vulkan/Pipeline.h"
#include "render/vulkan/Spirv.h"
#include "render/vulkan/VkCheck.h"
#include "support/GpuCompute.h"
#include "util/Error.h"

using namespace pyrolume;
using namespace pyrolume::vk;

namespace {

// Sets (or unsets) an environment variable for one scope.
class EnvGuard {
 public:
  EnvGuard(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value)
      setenv(name, value, 1);
    else
      unsetenv(name);
  }
  ~EnvGuard() {
    if (old_)
      setenv(name_, old_->c_str(), 1);
    else
      unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

DeviceInfo fake(uint32_t index, VkPhysicalDeviceType type) {
  DeviceInfo d;
  d.index = index;
  d.name = "fake " + std::to_string(index);
  d.type = type;
  d.type_name = device_type_name(type);
  d.api_version = VK_API_VERSION_1_3;
  d.device_local_bytes = 1ull << 30;
  return d;
}

// shaders/test_fill.comp's interface: its bindings, its push constants
// (count, offset, sample_count) and the set that binds them.
const std::vector<ComputePipeline::Binding> kTestFillBindings = {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                                                                 {1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER},
                                                                 {2, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER},
                                                                 {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}};
struct TestFillPush {
  uint32_t count, offset, sample_count;
};
void bind_test_fill(DescriptorSet& set, Buffer& values, Image3D& grid, Image1D& table, Buffer& samples) {
  set.write_buffer(0, values);
  set.write_image(1, grid);
  set.write_image(2, table.view(), table.sampler());
  set.write_buffer(3, samples);
}

}  // namespace

TEST(VkCheck, ReportsExpressionResultAndPlace) {
  try {
    VK_CHECK(VK_ERROR_DEVICE_LOST);
    FAIL() << "VK_CHECK did not throw";
  } catch (const VulkanError& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find("VK_ERROR_DEVICE_LOST"), std::string::npos) << msg;
    EXPECT_NE(msg.find("vk_context_test.cpp:"), std::string::npos) << msg;
    EXPECT_EQ(e.result, VK_ERROR_DEVICE_LOST);
  }
  EXPECT_NO_THROW(VK_CHECK(VK_SUCCESS));
  EXPECT_STREQ(vk_result_name(VK_ERROR_OUT_OF_DEVICE_MEMORY), "VK_ERROR_OUT_OF_DEVICE_MEMORY");
}

TEST(Handles, UniqueDestroysOnceAndMoves) {
  static int destroyed = 0;
  struct CountingDeleter {
    void operator()(VkFence) const { ++destroyed; }
  };
  using U = Unique<VkFence, CountingDeleter>;
  destroyed = 0;
  {
    U a(reinterpret_cast<VkFence>(uintptr_t(0x10)), {});
    U b(std::move(a));
    EXPECT_FALSE(a);
    EXPECT_TRUE(b);
    U c(reinterpret_cast<VkFence>(uintptr_t(0x20)), {});
    c = std::move(b);  // destroys c's own handle
    EXPECT_EQ(destroyed, 1);
  }
  EXPECT_EQ(destroyed, 2);
}

TEST(ChooseDevice, PrefersDiscreteThenIntegratedThenCpu) {
  EnvGuard env("PYROLUME_DEVICE", nullptr);
  EXPECT_EQ(choose_device({fake(0, VK_PHYSICAL_DEVICE_TYPE_CPU), fake(1, VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU),
                           fake(2, VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU)},
                          -1),
            2);
  EXPECT_EQ(choose_device({fake(0, VK_PHYSICAL_DEVICE_TYPE_CPU), fake(1, VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU)}, -1),
            1);
  EXPECT_EQ(choose_device({fake(0, VK_PHYSICAL_DEVICE_TYPE_CPU), fake(1, VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU)}, -1), 1);
  EXPECT_EQ(choose_device({fake(0, VK_PHYSICAL_DEVICE_TYPE_OTHER), fake(1, VK_PHYSICAL_DEVICE_TYPE_CPU)}, -1), 1);
  // Ties go to the lower index.
  EXPECT_EQ(choose_device({fake(0, VK_PHYSICAL_DEVICE_TYPE_CPU), fake(1, VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU),
                           fake(2, VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU)},
                          -1),
            1);
  EXPECT_EQ(choose_device({fake(0, VK_PHYSICAL_DEVICE_TYPE_CPU)}, -1), 0);
}

TEST(ChooseDevice, RequestAndEnvironmentOverride) {
  const std::vector<DeviceInfo> devs = {fake(0, VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU),
                                        fake(1, VK_PHYSICAL_DEVICE_TYPE_CPU)};
  {
    EnvGuard env("PYROLUME_DEVICE", nullptr);
    EXPECT_EQ(choose_device(devs, 1), 1);
  }
  {
    EnvGuard env("PYROLUME_DEVICE", "1");
    EXPECT_EQ(choose_device(devs, -1), 1);
    EXPECT_EQ(choose_device(devs, 0), 0);  // an explicit --device wins over the environment
  }
}

TEST(ChooseDevice, OutOfRangeIsAnInputErrorThatCountsDevices) {
  const std::vector<DeviceInfo> devs = {fake(0, VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU),
                                        fake(1, VK_PHYSICAL_DEVICE_TYPE_CPU)};
  EnvGuard env("PYROLUME_DEVICE", nullptr);
  try {
    choose_device(devs, 2);
    FAIL() << "no throw";
  } catch (const InputError& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find("--device 2"), std::string::npos) << msg;
    EXPECT_NE(msg.find("2 Vulkan devices"), std::string::npos) << msg;
  }
  for (const char* bad : {"2", "-1", "abc", "1x"}) {
    EnvGuard env2("PYROLUME_DEVICE", bad);
    try {
      choose_device(devs, -1);
      FAIL() << "no throw for PYROLUME_DEVICE=" << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("PYROLUME_DEVICE"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(choose_device({}, -1), NoDeviceError);
  try {
    choose_device({}, -1);
  } catch (const NoDeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("--backend cpu"), std::string::npos) << e.what();
  }
}

TEST(Devices, FormatMarksTheChosenDevice) {
  std::string text = format_device_list(
      {fake(0, VK_PHYSICAL_DEVICE_TYPE_CPU), fake(1, VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU)}, 1);
  EXPECT_NE(text.find("  0: fake 0 | cpu | Vulkan 1.3.0 | 1.0 GiB\n"), std::string::npos) << text;
  EXPECT_NE(text.find("* 1: fake 1 | discrete | Vulkan 1.3.0 | 1.0 GiB (default)\n"), std::string::npos) << text;
}

TEST(Devices, ListingFindsLavapipe) {
  std::vector<DeviceInfo> devs = list_devices();
  ASSERT_FALSE(devs.empty());
  bool found = false;
  for (size_t i = 0; i < devs.size(); ++i) {
    EXPECT_EQ(devs[i].index, i);
    EXPECT_GE(devs[i].api_version, VK_API_VERSION_1_2) << devs[i].name;
    if (devs[i].driver_name == "llvmpipe" || devs[i].name.find("llvmpipe") != std::string::npos) {
      found = true;
      EXPECT_EQ(devs[i].type, VK_PHYSICAL_DEVICE_TYPE_CPU);
      EXPECT_EQ(devs[i].type_name, "cpu");
      EXPECT_GT(devs[i].device_local_bytes, 0u);
    }
  }
  EXPECT_TRUE(found) << format_device_list(devs, -1);
}

TEST(Spirv, MissingShaderNamesBothPlaces) {
  try {
    load_spirv("no_such_shader.comp");
    FAIL() << "no throw";
  } catch (const std::runtime_error& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find("no_such_shader.comp.spv"), std::string::npos) << msg;
    EXPECT_NE(msg.find(PYROLUME_SPIRV_DIR), std::string::npos) << msg;
    EXPECT_NE(msg.find(" or "), std::string::npos) << msg;
  }
  EXPECT_FALSE(load_spirv("test_fill.comp").empty());
}

TEST(VulkanContext, BuffersRoundTripAndHugeAllocationsFailClearly) {
  const uint64_t before = Context::total_validation_messages();
  {
    Context ctx(test::validated());
    EXPECT_TRUE(ctx.validation_enabled());
    std::vector<float> data(1000);
    for (size_t i = 0; i < data.size(); ++i) data[i] = float(i) * 0.25f;
    // DeviceLocal goes through staging buffers both ways (unmapped on a real GPU;
    // lavapipe maps it, so also test an explicitly host-visible pair).
    Buffer local(ctx, data.size() * 4,
                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                 MemoryKind::DeviceLocal, "roundtrip local");
    local.upload(ctx, data.data(), data.size() * 4);
    Buffer readback(ctx, data.size() * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryKind::Readback, "roundtrip readback");
    ctx.submit_and_wait([&](VkCommandBuffer cmd) {
      VkBufferCopy copy{0, 0, data.size() * 4};
      vkCmdCopyBuffer(cmd, local.buffer(), readback.buffer(), 1, &copy);
      to_host_read_barrier(cmd);
    });
    readback.invalidate();
    EXPECT_EQ(std::memcmp(readback.map(), data.data(), data.size() * 4), 0);
    std::vector<float> back(data.size());
    local.download(ctx, back.data(), back.size() * 4);
    EXPECT_EQ(back, data);

    try {
      Buffer huge(ctx, VkDeviceSize(1) << 50, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::DeviceLocal, "huge");
      FAIL() << "no throw";
    } catch (const VulkanError& e) {
      std::string msg = e.what();
      EXPECT_NE(msg.find("'huge'"), std::string::npos) << msg;
      EXPECT_NE(msg.find("1073741824.0 MiB"), std::string::npos) << msg;
    }
    EXPECT_EQ(ctx.validation_messages(), 0u);
  }
  EXPECT_EQ(Context::total_validation_messages(), before) << "validation messages while destroying the context";
}

TEST(VulkanContext, RunsComputeShaderWithImagesUnderValidation) {
  const uint64_t before = Context::total_validation_messages();
  {
    Context ctx(test::validated());
    EXPECT_TRUE(ctx.validation_enabled());
    EXPECT_GE(ctx.properties().apiVersion, VK_API_VERSION_1_2);
    EXPECT_EQ(ctx.info().name, ctx.properties().deviceName);

    // Grid f(x,y,z) = x + 10y + 100z at texel centres: trilinear filtering
    // reproduces a linear function exactly between centres.
    const uint32_t N = 4;
    std::vector<float> grid(N * N * N);
    for (uint32_t z = 0; z < N; ++z)
      for (uint32_t y = 0; y < N; ++y)
        for (uint32_t x = 0; x < N; ++x) grid[(z * N + y) * N + x] = float(x + 10 * y + 100 * z);
    Image3D image3d(ctx, N, N, N, VK_FORMAT_R32_SFLOAT, "test grid");
    image3d.upload(ctx, grid.data(), grid.size() * sizeof(float));
    const uint32_t M = 8;
    std::vector<float> table(M * 4);
    for (uint32_t i = 0; i < M; ++i) {
      table[i * 4 + 0] = float(i);
      table[i * 4 + 1] = float(i) * 2.0f;
    }
    Image1D image1d(ctx, M, VK_FORMAT_R32G32B32A32_SFLOAT, "test table");
    image1d.upload(ctx, table.data(), table.size() * sizeof(float));

    struct Sample {
      float coord[4];
      float result[4];
    };
    auto c = [](float i) { return (i + 0.5f) / float(N); };  // texel i's centre
    auto t = [](float i) { return (i + 0.5f) / float(M); };
    std::vector<Sample> samples = {
        {{c(0), c(0), c(0), t(0)}, {}},            // corner texel; table row 0
        {{c(3), c(2), c(1), t(7)}, {}},            // texel (3,2,1); last table row
        {{c(1.5f), c(0.5f), c(2.5f), t(2.5f)}, {}},  // half-way between centres
        {{-0.6f, 0.5f, 0.5f, -1.0f}, {}},          // far outside: border 0; table clamps to row 0
        {{0.5f, 1.6f, 0.5f, 2.0f}, {}},            // far outside: border 0; table clamps to row 7
    };
    const std::vector<float> want_grid = {0, 3 + 20 + 100, 1.5f + 5 + 250, 0, 0};
    const std::vector<float> want_table = {0, 7, 2.5f, 0, 7};
    Buffer sample_buf(ctx, samples.size() * sizeof(Sample), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::HostVisible,
                      "test samples");
    sample_buf.upload(ctx, samples.data(), samples.size() * sizeof(Sample));

    const uint32_t count = 1000;
    Buffer values(ctx, count * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::Readback, "test values");

    ComputePipeline pipeline(ctx, load_spirv("test_fill.comp"), kTestFillBindings, sizeof(TestFillPush), {{0, 2u}},
                             "test_fill");
    DescriptorSet set(ctx, pipeline);
    bind_test_fill(set, values, image3d, image1d, sample_buf);

    const TestFillPush push{count, 7, uint32_t(samples.size())};
    test::dispatch_and_wait(ctx, pipeline, set, count, push);

    values.invalidate();
    const uint32_t* v = values.data<uint32_t>();
    for (uint32_t i = 0; i < count; ++i) ASSERT_EQ(v[i], i * 2 + 7) << "at " << i;

    std::vector<Sample> got(samples.size());
    sample_buf.download(ctx, got.data(), got.size() * sizeof(Sample));
    for (size_t i = 0; i < got.size(); ++i) {
      EXPECT_NEAR(got[i].result[0], want_grid[i], 1e-3f * (1 + want_grid[i])) << "grid sample " << i;
      EXPECT_NEAR(got[i].result[1], want_table[i], 1e-3f * (1 + want_table[i])) << "table sample " << i;
      EXPECT_NEAR(got[i].result[2], 2 * want_table[i], 2e-3f * (1 + want_table[i])) << "table sample " << i;
    }
    EXPECT_EQ(ctx.validation_messages(), 0u);
  }
  EXPECT_EQ(Context::total_validation_messages(), before) << "validation messages while destroying the context";
}

// The device's pipeline cache (Pipeline.h PipelineCache): the same shader,
// bindings, push-constant size, specialisation and name give the same
// pipeline; any one of them different gives another; past kCapacity the
// least recently used is made again; and a shared pipeline computes what its
// own specialisation says (MULTIPLIER 2 and 3 of test_fill.comp).
TEST(VulkanContext, PipelineCacheSharesOnlyIdenticalPipelines) {
  const uint64_t before = Context::total_validation_messages();
  {
    Context ctx(test::validated());
    const std::vector<uint32_t> code = load_spirv("test_fill.comp");
    const std::vector<ComputePipeline::Binding>& bindings = kTestFillBindings;
    const uint32_t push_bytes = sizeof(TestFillPush);
    PipelineCache& cache = ctx.pipelines();
    auto get = [&](uint32_t multiplier, const char* name = "fill") {
      return cache.get(code, bindings, push_bytes, {{0, multiplier}}, name);
    };
    const auto two = get(2);
    EXPECT_EQ(get(2), two);
    EXPECT_NE(get(3), two);
    EXPECT_NE(get(2, "other name"), two);
    EXPECT_NE(cache.get(code, bindings, push_bytes + 4, {{0, 2u}}, "fill"), two);
    auto more = bindings;  // a binding the shader does not use: a valid, different layout
    more.push_back({4, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
    EXPECT_NE(cache.get(code, more, push_bytes, {{0, 2u}}, "fill"), two);
    EXPECT_EQ(get(2), two);  // still kept: the most recently used

    // Each pipeline runs with its own constant: v[i] = i * MULTIPLIER + offset.
    const uint32_t count = 64;
    for (const uint32_t multiplier : {2u, 3u}) {
      Buffer values(ctx, count * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::Readback, "test values");
      const std::vector<float> texel(4, 0.0f);
      Image3D image3d(ctx, 1, 1, 1, VK_FORMAT_R32_SFLOAT, "test grid");
      image3d.upload(ctx, texel.data(), sizeof(float));
      Image1D image1d(ctx, 1, VK_FORMAT_R32G32B32A32_SFLOAT, "test table");
      image1d.upload(ctx, texel.data(), texel.size() * sizeof(float));
      Buffer samples(ctx, 64, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::HostVisible, "test samples");
      const auto pipeline = get(multiplier);
      DescriptorSet set(ctx, *pipeline);
      bind_test_fill(set, values, image3d, image1d, samples);
      const TestFillPush push{count, 5, 0};
      test::dispatch_and_wait(ctx, *pipeline, set, count, push);
      values.invalidate();
      const uint32_t* v = values.data<uint32_t>();
      for (uint32_t i = 0; i < count; ++i) ASSERT_EQ(v[i], i * multiplier + 5) << "multiplier " << multiplier;
    }

    // Past kCapacity other pipelines, the first is made again.
    for (uint32_t m = 10; m < 10 + PipelineCache::kCapacity; ++m) get(m);
    EXPECT_NE(get(2), two);
    EXPECT_EQ(ctx.validation_messages(), 0u);
  }
  EXPECT_EQ(Context::total_validation_messages(), before) << "validation messages while destroying the context";
}
