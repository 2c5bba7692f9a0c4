// `pyrolume preview`: the progressive render in a GLFW window (issue 7).
//
// One queue renders and presents. Each display frame records, in one command
// buffer: a pass of samples (RenderSession::record_pass), the display shader
// (accumulation -> 8-bit sRGB pixels) and a copy into the acquired swapchain
// image. One frame is in flight: the loop waits for it, which is also how the
// pass is timed to choose the next frame's sample count.
#include "preview/Preview.h"

// Vulkan structs are written {.sType = ...}: the rest is zero by design.
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <stb_image_write.h>

#include "image/AtomicFile.h"
#include "image/DisplayTransform.h"
#include "image/ImageIo.h"
#include "preview/DisplayPass.h"
#include "preview/OrbitCamera.h"
#include "preview/PreviewHandles.h"
#include "preview/PreviewInput.h"
#include "preview/Swapchain.h"
#include "render/RenderImage.h"
#include "render/vulkan/Context.h"
#include "render/vulkan/RenderSession.h"
#include "render/vulkan/VkCheck.h"
#include "render/SceneSetup.h"
#include "scene/Scene.h"
#include "util/Error.h"

namespace pyrolume {
namespace {

using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

// Set by SIGINT/SIGTERM: the loop ends after the current frame, as the window's
// close button would, and the command exits 130/143 (README.md "Using it").
std::atomic<int> g_signal{0};
extern "C" void on_preview_signal(int sig) { g_signal = sig; }

// GLFW reports why glfwInit or window creation failed through this callback only.
std::string g_glfw_error;
void on_glfw_error(int, const char* description) { g_glfw_error = description ? description : "unknown error"; }

constexpr double kTargetFrameSeconds = 1.0 / 30.0;  // the issue: hold about 30 fps
constexpr int kMaxSppPerFrame = 4096;
// After this many samples per pixel the preview stops sampling and only
// redraws: an idle window must not keep the GPU busy forever. Not a render's
// spp limit (kMaxSpp): the preview keeps sampling past film.spp up to this.
constexpr int kPreviewStopSpp = 1 << 16;
constexpr double kOrbitRadPerPixel = 0.005;
constexpr double kExposureStep = 0.5;       // stops per key press
constexpr double kTemperatureStep = 1.05;   // factor per key press
// Auto exposure follows the image until it has this many samples per pixel,
// then holds (docs/view-transform.md): a noisy first frame must not decide.
constexpr int kAutoExposureSpp = 16;

const char* kControls =
    "left drag: orbit, right/middle drag: pan, wheel: zoom, +/-: exposure, V: view, [ ]: temperature scale, R: reset, "
    "S: save, Esc: quit";

std::string render_hint(const std::string& scene) {
  return "use `pyrolume render " + scene + " -o out.png` instead";
}

std::string timestamp() {
  std::time_t t = std::time(nullptr);
  std::tm tm{};
  localtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", &tm);
  return buf;
}

// 8-bit RGB exactly as shown (no re-encoding), written atomically.
void write_png_bytes(const fs::path& file, const std::vector<uint8_t>& rgb, uint32_t width, uint32_t height) {
  write_file_atomic(file, [&](std::ostream& os) {
    auto sink = [](void* ctx, void* data, int size) { static_cast<std::ostream*>(ctx)->write((const char*)data, size); };
    if (!stbi_write_png_to_func(sink, &os, int(width), int(height), 3, rgb.data(), int(width) * 3))
      throw std::runtime_error("PNG encoding failed");
  });
}

class PreviewWindow {
 public:
  PreviewWindow(const PreviewArgs& args, Scene scene);
  ~PreviewWindow();
  PreviewWindow(const PreviewWindow&) = delete;
  PreviewWindow& operator=(const PreviewWindow&) = delete;

  // Runs until closed, Esc, a signal, or args.frames display frames.
  void run();
  void save_screenshot(const fs::path& file);
  void print_summary() const;

 private:
  void apply_input();
  void save_accumulation();
  bool ensure_swapchain();
  void draw_frame();
  void update_title(bool force);
  void pace(int pass_spp, double pass_seconds, double period);
  void follow_auto_exposure();
  int first_grid_medium() const;

  const PreviewArgs& args_;
  const Scene original_;
  Scene scene_;
  RenderSettings settings_;
  DisplayExposure exposure_choice_;  // --exposure, else film.exposure (or auto)
  double exposure_;
  bool auto_exposure_held_ = false;  // auto exposure chosen for good (or the user took over with +/-)
  Input input_;

  // Declared in creation order; destroyed in reverse (surface before instance,
  // window after its surface, GLFW last).
  preview::GlfwLibrary glfw_;
  preview::UniqueWindow window_;
  std::unique_ptr<vk::Context> ctx_;
  preview::UniqueSurface surface_;
  std::optional<RenderSession> session_;
  std::optional<preview::DisplayPass> display_;
  std::optional<preview::Swapchain> swapchain_;
  vk::UniqueCommandPool pool_;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;  // freed with the pool
  vk::UniqueFence frame_done_;
  vk::UniqueSemaphore image_acquired_;
  vk::UniqueQueryPool timestamps_;  // around each frame's pass; empty when the queue has no timestamps

  int frames_shown_ = 0;
  int spp_per_frame_ = 1;
  double seconds_per_spp_ = 0.0;   // smoothed cost of one sample per pixel
  double overhead_seconds_ = 0.0;  // smoothed frame period minus the pass
  std::optional<Clock::time_point> last_frame_end_;
  double msamples_per_s_ = 0.0;
  Clock::time_point last_title_{};
  std::string note_;  // a transient message in the title (e.g. "[ ]: no grid medium")
  Clock::time_point note_until_{};
};

PreviewWindow::PreviewWindow(const PreviewArgs& args, Scene scene)
    : args_(args),
      original_(scene),
      scene_(std::move(scene)),
      exposure_choice_(parse_exposure(args.exposure)),
      exposure_(exposure_choice_.automatic(scene_.film) ? 0.0 : exposure_choice_.stops(scene_.film, Image())) {
  settings_.width = args.width.value_or(scene_.film.width);
  settings_.height = args.height.value_or(scene_.film.height);
  settings_.spp = scene_.film.spp;
  settings_.seed = scene_.film.seed;

  const std::string hint = render_hint(args.scene);
  if (!glfw_.ok()) throw preview::NoDisplayError("cannot open a window (GLFW: " + g_glfw_error + ")");
  if (!glfwVulkanSupported()) throw preview::NoDisplayError("GLFW finds no Vulkan loader for windows");
  uint32_t next = 0;
  const char** required = glfwGetRequiredInstanceExtensions(&next);
  if (!required) throw preview::NoDisplayError("this display has no Vulkan surface extension (GLFW: " + g_glfw_error + ")");

  // The window starts at the render size, shrunk (aspect kept) to fit the screen.
  int win_w = settings_.width, win_h = settings_.height;
  if (GLFWmonitor* monitor = glfwGetPrimaryMonitor()) {
    int mx = 0, my = 0, mw = 0, mh = 0;
    glfwGetMonitorWorkarea(monitor, &mx, &my, &mw, &mh);
    if (mw > 0 && mh > 0) {
      const double s = std::min({1.0, 0.9 * mw / win_w, 0.9 * mh / win_h});
      win_w = std::max(1, int(win_w * s));
      win_h = std::max(1, int(win_h * s));
    }
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
  window_.reset(glfwCreateWindow(win_w, win_h, "pyrolume preview", nullptr, nullptr));
  if (!window_) throw preview::NoDisplayError("cannot create a window (GLFW: " + g_glfw_error + ")");
  GLFWwindow* w = window_.get();
  install_input_callbacks(w, &input_);

  vk::Context::Options options;
  options.device_index = args.device;
  options.instance_extensions.assign(required, required + next);
  options.device_extensions = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
  try {
    ctx_ = std::make_unique<vk::Context>(options);
  } catch (const vk::VulkanError& e) {
    // Surface or swapchain extension missing: this device/driver cannot show windows.
    if (e.result == VK_ERROR_EXTENSION_NOT_PRESENT)
      throw preview::NoDisplayError(std::string("the Vulkan driver cannot present to windows (") + e.what() + ")");
    throw;
  }
  VkSurfaceKHR surface = VK_NULL_HANDLE;
  VkResult r = glfwCreateWindowSurface(ctx_->instance(), w, nullptr, &surface);
  if (r != VK_SUCCESS)
    throw preview::NoDisplayError(std::string("cannot create a Vulkan surface for the window (") +
                                  vk::vk_result_name(r) + ")");
  surface_ = preview::UniqueSurface(surface, {ctx_->instance()});
  VkBool32 supported = VK_FALSE;
  VK_CHECK(vkGetPhysicalDeviceSurfaceSupportKHR(ctx_->physical_device(), ctx_->queue_family(), surface, &supported));
  if (!supported)
    throw preview::NoDisplayError("Vulkan device " + ctx_->info().name + " cannot present to this display");

  session_.emplace(*ctx_, scene_, settings_);
  for (const std::string& warning : session_->warnings()) std::cerr << "pyrolume: warning: " << warning << "\n";
  display_.emplace(*ctx_, session_->accumulation(), session_->accumulation_texel_bytes(), uint32_t(settings_.width),
                   uint32_t(settings_.height));
  swapchain_.emplace(*ctx_, surface);

  VkDevice dev = ctx_->device();
  VkCommandPoolCreateInfo pci{.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = ctx_->queue_family();
  VkCommandPool pool = VK_NULL_HANDLE;
  VK_CHECK(vkCreateCommandPool(dev, &pci, nullptr, &pool));
  pool_ = vk::UniqueCommandPool(pool, {dev});
  VkCommandBufferAllocateInfo cai{.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cai.commandPool = pool;
  cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cai.commandBufferCount = 1;
  VK_CHECK(vkAllocateCommandBuffers(dev, &cai, &cmd_));
  VkFenceCreateInfo fci{.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence = VK_NULL_HANDLE;
  VK_CHECK(vkCreateFence(dev, &fci, nullptr, &fence));
  frame_done_ = vk::UniqueFence(fence, {dev});
  VkSemaphoreCreateInfo sci{.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  VkSemaphore sem = VK_NULL_HANDLE;
  VK_CHECK(vkCreateSemaphore(dev, &sci, nullptr, &sem));
  image_acquired_ = vk::UniqueSemaphore(sem, {dev});
  if (ctx_->timestamp_period_ns() > 0) {
    VkQueryPoolCreateInfo qci{.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    qci.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qci.queryCount = 2;
    VkQueryPool qp = VK_NULL_HANDLE;
    VK_CHECK(vkCreateQueryPool(dev, &qci, nullptr, &qp));
    timestamps_ = vk::UniqueQueryPool(qp, {dev});
    ctx_->set_name(qp, "preview pass timestamps");
  }
  ctx_->set_name(pool, "preview command pool");
  ctx_->set_name(cmd_, "preview frame commands");
  ctx_->set_name(fence, "preview frame done");
  ctx_->set_name(sem, "preview image acquired");
  update_title(true);
}

PreviewWindow::~PreviewWindow() {
  // Presentation may still read a swapchain image or wait on a semaphore.
  if (ctx_) vkDeviceWaitIdle(ctx_->device());
}

int PreviewWindow::first_grid_medium() const {
  for (size_t i = 0; i < scene_.media.size(); ++i)
    if (scene_.media[i].type == Medium::Type::Vdb) return int(i);
  return -1;
}

void PreviewWindow::apply_input() {
  Input& in = input_;
  bool changed = false;
  if (in.reset) {
    // Back to the scene as loaded: view, exposure and temperature scale.
    scene_ = original_;
    exposure_choice_.forget_auto();
    auto_exposure_held_ = false;
    exposure_ = exposure_choice_.automatic(scene_.film) ? 0.0 : exposure_choice_.stops(scene_.film, Image());
    changed = true;
  }
  if (in.orbit_x != 0 || in.orbit_y != 0) {
    // Drag right: the scene turns right (the camera goes left); drag down: look from higher up.
    preview::orbit(scene_.camera, -in.orbit_x * kOrbitRadPerPixel, -in.orbit_y * kOrbitRadPerPixel);
    changed = true;
  }
  if (in.pan_x != 0 || in.pan_y != 0) {
    // Pixels of the window -> pixels of the render (the image is scaled to fit).
    const double scale = display_->rect().height > 0 ? double(settings_.height) / display_->rect().height : 1.0;
    int ww = 0, wh = 0, fw = 0, fh = 0;
    glfwGetWindowSize(window_.get(), &ww, &wh);
    glfwGetFramebufferSize(window_.get(), &fw, &fh);
    const double dpi = ww > 0 ? double(fw) / ww : 1.0;  // cursor in screen units, framebuffer in pixels
    preview::pan(scene_.camera, in.pan_x * dpi * scale, in.pan_y * dpi * scale, settings_.height);
    changed = true;
  }
  if (in.zoom != 0) {
    preview::zoom(scene_.camera, in.zoom);
    changed = true;
  }
  if (in.exposure_steps != 0) {
    exposure_ += kExposureStep * in.exposure_steps;  // display only: no restart
    auto_exposure_held_ = true;                      // the user's choice from here on
  }
  if (in.view_steps != 0) {
    // The next view in kViewTransforms' order: display only, no restart.
    const int n = int(std::size(kViewTransforms));
    int at = 0;
    while (at < n && kViewTransforms[at] != scene_.film.view) ++at;
    scene_.film.view = kViewTransforms[((at + in.view_steps) % n + n) % n];
  }
  if (in.temperature_steps != 0) {
    const int i = first_grid_medium();
    if (i < 0) {
      note_ = "[ ]: no grid (vdb) medium in this scene";
      note_until_ = Clock::now() + std::chrono::seconds(3);
    } else {
      scene_.media[size_t(i)].temperature.scale *= std::pow(kTemperatureStep, in.temperature_steps);
      changed = true;
    }
  }
  const bool save = in.save;
  const bool exposure_changed = in.exposure_steps != 0 || in.view_steps != 0;
  const bool resized = in.framebuffer_resized;
  in = Input{in.last_x, in.last_y, in.have_last};
  in.framebuffer_resized = resized;
  if (changed) session_->update(scene_);  // restarts the accumulation
  if (save) save_accumulation();
  if (changed || exposure_changed || save) update_title(true);
}

void PreviewWindow::save_accumulation() {
  const fs::path scene_file(args_.scene);
  const fs::path base = scene_file.parent_path() / (scene_file.stem().string() + "_preview_" + timestamp());
  RenderResult result;
  session_->read(result);
  Image image = image_from_render(result, /*with_variance=*/true);
  image.transparent = scene_.film.transparent;
  const fs::path exr = base.string() + ".exr", png = base.string() + ".png";
  try {
    write_image(exr, image);
    write_image(png, image, exposure_, scene_.film.view);
    std::cout << exr.string() << "\n" << png.string() << std::endl;
    note_ = "saved " + png.filename().string();
  } catch (const std::exception& e) {
    // A failed save (read-only folder) must not end the session.
    std::cerr << "pyrolume: preview: cannot save: " << e.what() << "\n";
    note_ = "save failed";
  }
  note_until_ = Clock::now() + std::chrono::seconds(3);
}

bool PreviewWindow::ensure_swapchain() {
  int fw = 0, fh = 0;
  glfwGetFramebufferSize(window_.get(), &fw, &fh);
  if (fw <= 0 || fh <= 0) return false;  // minimised
  const VkExtent2D want{uint32_t(fw), uint32_t(fh)};
  if (*swapchain_ && !input_.framebuffer_resized) return true;
  vkDeviceWaitIdle(ctx_->device());  // the old swapchain's images and the display buffer may be in use
  input_.framebuffer_resized = false;
  if (!swapchain_->recreate(want)) return false;
  display_->resize(swapchain_->extent(), swapchain_->bgra());
  return true;
}

void PreviewWindow::draw_frame() {
  VkDevice dev = ctx_->device();
  uint32_t index = 0;
  VkResult r = vkAcquireNextImageKHR(dev, swapchain_->get(), UINT64_MAX, image_acquired_.get(), VK_NULL_HANDLE, &index);
  if (r == VK_ERROR_OUT_OF_DATE_KHR) {
    input_.framebuffer_resized = true;
    return;
  }
  if (r == VK_SUBOPTIMAL_KHR)
    input_.framebuffer_resized = true;  // the semaphore is signalled: use this image, recreate after
  else
    VK_CHECK(r);

  const int pass_spp = session_->spp_done() >= kPreviewStopSpp ? 0 : spp_per_frame_;
  VK_CHECK(vkResetCommandBuffer(cmd_, 0));
  VkCommandBufferBeginInfo bi{.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(cmd_, &bi));
  // The last frame's display shader and copy read the accumulation and the
  // display buffer that this frame's pass and display shader overwrite.
  vk::memory_barrier(cmd_, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                     VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                     VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                         VK_ACCESS_TRANSFER_WRITE_BIT);
  if (timestamps_) {
    vkCmdResetQueryPool(cmd_, timestamps_.get(), 0, 2);
    vkCmdWriteTimestamp(cmd_, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, timestamps_.get(), 0);
  }
  if (pass_spp > 0) session_->record_pass(cmd_, pass_spp);
  if (timestamps_) vkCmdWriteTimestamp(cmd_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, timestamps_.get(), 1);
  display_->record(cmd_, session_->spp_done(), exposure_, scene_.film.view, swapchain_->image(index));
  VK_CHECK(vkEndCommandBuffer(cmd_));

  VkSemaphore wait = image_acquired_.get();
  VkSemaphore signal = swapchain_->render_finished(index);
  VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;  // only the copy touches the image
  VkSubmitInfo si{.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.waitSemaphoreCount = 1;
  si.pWaitSemaphores = &wait;
  si.pWaitDstStageMask = &wait_stage;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd_;
  si.signalSemaphoreCount = 1;
  si.pSignalSemaphores = &signal;
  VkFence fence = frame_done_.get();
  VK_CHECK(vkResetFences(dev, 1, &fence));
  const auto t0 = Clock::now();
  VK_CHECK(vkQueueSubmit(ctx_->queue(), 1, &si, fence));

  VkSwapchainKHR sc = swapchain_->get();
  VkPresentInfoKHR pi{.sType = VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  pi.waitSemaphoreCount = 1;
  pi.pWaitSemaphores = &signal;
  pi.swapchainCount = 1;
  pi.pSwapchains = &sc;
  pi.pImageIndices = &index;
  r = vkQueuePresentKHR(ctx_->queue(), &pi);
  if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR)
    input_.framebuffer_resized = true;
  else
    VK_CHECK(r);
  VK_CHECK(vkWaitForFences(dev, 1, &fence, VK_TRUE, UINT64_MAX));
  const auto done = Clock::now();
  const double fence_seconds = std::chrono::duration<double>(done - t0).count();
  frames_shown_++;

  // How long the samples took: GPU timestamps where the queue has them (on
  // lavapipe the work runs inside vkQueuePresentKHR and the fence wait, mixed
  // with presentation), else the whole submit-to-fence time (an overestimate).
  double pass_seconds = fence_seconds;
  if (timestamps_ && pass_spp > 0) {
    uint64_t ticks[2] = {0, 0};
    if (vkGetQueryPoolResults(dev, timestamps_.get(), 0, 2, sizeof ticks, ticks, sizeof(uint64_t),
                              VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT) == VK_SUCCESS &&
        ticks[1] > ticks[0])
      pass_seconds = double(ticks[1] - ticks[0]) * ctx_->timestamp_period_ns() * 1e-9;
  }
  const double period = last_frame_end_ ? std::chrono::duration<double>(done - *last_frame_end_).count() : fence_seconds;
  last_frame_end_ = done;
  pace(pass_spp, pass_seconds, period);
}

void PreviewWindow::pace(int pass_spp, double pass_seconds, double period) {
  // frame period = overhead (events, display, presentation) + spp × cost per
  // sample. Both are smoothed; the next sample count fills what the ~30 fps
  // budget leaves after the overhead, but at least half the budget (a slow
  // display must not starve the render), growing at most 2x a frame.
  if (pass_spp <= 0 || !(pass_seconds > 0)) return;
  auto smooth = [](double& avg, double x) { avg = avg > 0 ? 0.7 * avg + 0.3 * x : x; };
  smooth(seconds_per_spp_, pass_seconds / pass_spp);
  smooth(overhead_seconds_, std::max(period - pass_seconds, 1e-6));
  const double budget = std::max(kTargetFrameSeconds - overhead_seconds_, 0.5 * kTargetFrameSeconds);
  const int want = int(budget / seconds_per_spp_);
  spp_per_frame_ = std::clamp(want, 1, std::min(kMaxSppPerFrame, 2 * pass_spp));
  const double ms = double(settings_.width) * settings_.height * pass_spp / pass_seconds * 1e-6;
  msamples_per_s_ = msamples_per_s_ > 0 ? 0.8 * msamples_per_s_ + 0.2 * ms : ms;
}

// With auto exposure: choose it again from the accumulation so far (a
// readback) before each frame, until kAutoExposureSpp samples per pixel; then
// print the choice and hold it.
void PreviewWindow::follow_auto_exposure() {
  if (auto_exposure_held_ || !exposure_choice_.automatic(scene_.film) || session_->spp_done() <= 0) return;
  RenderResult result;
  session_->read(result);
  const Image image = image_from_render(result, /*with_variance=*/false);
  const bool hold = session_->spp_done() >= kAutoExposureSpp;
  exposure_choice_.forget_auto();
  exposure_ = exposure_choice_.stops(scene_.film, image, hold ? &std::cerr : nullptr);
  auto_exposure_held_ = hold;
}

void PreviewWindow::update_title(bool force) {
  const auto now = Clock::now();
  if (!force && now - last_title_ < std::chrono::milliseconds(250)) return;
  last_title_ = now;
  if (!note_.empty() && now > note_until_) note_.clear();
  char head[256];
  std::snprintf(head, sizeof head, "pyrolume preview: %d spp%s | %.1f Msamples/s | %s | exposure %+.1f | view %s",
                session_->spp_done(), session_->spp_done() >= kPreviewStopSpp ? " (done)" : "", msamples_per_s_,
                ctx_->info().name.c_str(), exposure_, to_string(scene_.film.view));
  std::string title = head;
  if (int i = first_grid_medium(); i >= 0) {
    char t[64];
    std::snprintf(t, sizeof t, " | T scale %.3g", scene_.media[size_t(i)].temperature.scale);
    title += t;
  }
  if (!note_.empty()) title += " | " + note_;
  title += std::string(" | ") + kControls;
  glfwSetWindowTitle(window_.get(), title.c_str());
}

void PreviewWindow::run() {
  while (!glfwWindowShouldClose(window_.get()) && g_signal == 0) {
    // Converged: nothing to add, so wait for input instead of spinning.
    if (session_->spp_done() >= kPreviewStopSpp)
      glfwWaitEventsTimeout(0.1);
    else
      glfwPollEvents();
    apply_input();
    // Minimised (iconified, or a zero-size framebuffer where the platform does
    // that): nobody is watching, so render nothing until it comes back.
    if (glfwGetWindowAttrib(window_.get(), GLFW_ICONIFIED) || !ensure_swapchain()) {
      glfwWaitEventsTimeout(0.1);
      continue;
    }
    follow_auto_exposure();
    draw_frame();
    update_title(false);
    if (args_.frames > 0 && frames_shown_ >= args_.frames) break;
  }
}

void PreviewWindow::save_screenshot(const fs::path& file) {
  uint32_t w = 0, h = 0;
  std::vector<uint8_t> rgb = display_->read_shown(w, h);
  if (w == 0 || h == 0) throw std::runtime_error("preview: no frame was shown, so there is no screenshot to save");
  write_png_bytes(file, rgb, w, h);
}

void PreviewWindow::print_summary() const {
  std::printf("preview: %d frames, %d spp, %dx%d, %s\n", frames_shown_, session_->spp_done(), settings_.width,
              settings_.height, ctx_->info().name.c_str());
  std::fflush(stdout);
}

}  // namespace

bool preview_available() { return true; }

int run_preview_command(const PreviewArgs& args) {
  if (!args.screenshot.empty()) {
    const fs::path shot(args.screenshot);
    if (args.frames <= 0) {
      std::cerr << "pyrolume: preview: --screenshot needs --frames N (how many display frames to show first)\n";
      return 2;
    }
    if (lower_extension(shot) != ".png") {
      std::cerr << "pyrolume: " << args.screenshot << ": --screenshot writes PNG only (use a .png name)\n";
      return 2;
    }
    if (shot.has_parent_path() && !fs::is_directory(shot.parent_path())) {
      std::cerr << "pyrolume: " << args.screenshot << ": output folder does not exist\n";
      return 2;
    }
  }
  parse_exposure(args.exposure);         // InputError (a bad --exposure): exit 2
  const std::optional<ViewTransform> view = parse_view(args.view);  // and a bad --view
  Scene scene = load_scene(args.scene);  // InputError: the CLI prints it, exit 2
  if (view) scene.film.view = *view;
  // Source conventions, up axis and framing, as `render` settles them.
  const SceneSetup setup = complete_scene(scene, args.width || args.height || scene.film.size_given);
  for (const std::string& note : setup.notes) std::cerr << "pyrolume: note: " << note << "\n";
  // A frame pattern stands for its shot: the window shows the key frame, the
  // one whose file set the source convention, framing and exposure.
  if (setup.key_frame) {
    scene = scene_at_frame(scene, *setup.key_frame);
    std::cerr << "pyrolume: note: preview shows the shot's key frame " << *setup.key_frame
              << " (the middle of its frames on disk)\n";
  }

  g_signal = 0;
  auto old_int = std::signal(SIGINT, on_preview_signal);
  auto old_term = std::signal(SIGTERM, on_preview_signal);
  struct RestoreSignals {
    decltype(old_int) i, t;
    ~RestoreSignals() {
      std::signal(SIGINT, i);
      std::signal(SIGTERM, t);
    }
  } restore{old_int, old_term};

  glfwSetErrorCallback(on_glfw_error);
  try {
    PreviewWindow window(args, std::move(scene));
    if (args.frames <= 0) std::cerr << "pyrolume: preview: " << kControls << "\n";
    window.run();
    if (!args.screenshot.empty()) window.save_screenshot(args.screenshot);
    window.print_summary();
  } catch (const preview::NoDisplayError& e) {
    std::cerr << "pyrolume: preview: " << e.what() << "; " << render_hint(args.scene) << "\n";
    return 2;
  }
  if (g_signal == SIGINT) return 130;
  if (g_signal == SIGTERM) return 143;
  return 0;
}

}  // namespace pyrolume
