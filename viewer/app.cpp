#include "viewer/app.h"

#include <GL/glew.h>
#include <GLFW/glfw3.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "common/host_port.h"
#include "common/server_hint.h"
#include "viewer/clock.h"
#include "viewer/frame_pacer.h"
#include "viewer/frame_stats.h"
#include "viewer/hud.h"
#include "viewer/hud_text.h"
#include "viewer/input.h"
#include "viewer/live_plots.h"
#include "viewer/net/client.h"
#include "viewer/net/interpolation.h"
#include "viewer/net/snapshot_buffer.h"
#include "viewer/render/camera.h"
#include "viewer/render/screenshot.h"
#include "viewer/render/sphere_renderer.h"
#include "viewer/render/tank_outline.h"

namespace fishtank::viewer {
namespace {

constexpr int kWindowWidth = 1280;  // SPEC 5.2
constexpr int kWindowHeight = 1024;
constexpr float kPlayerSpeed = 8.0f;  // m/s; the server clamps at its own maximum
constexpr std::uint32_t kBallsPerPress = 1000;
constexpr float kOutlineGrow = 1.35f;
// The ring's outer radius at least, in logical pixels, so that a distant sphere is found.
constexpr float kOutlineMinPixels = 8.0f;
const std::array<std::uint8_t, 4> kOutlineRgba{255, 176, 32, 255};
constexpr float kHiddenAlpha = 0.8f;  // the own sphere's amber over the balls in front of it

struct GlfwSession {
  GlfwSession() { ok = glfwInit() == GLFW_TRUE; }
  ~GlfwSession() {
    if (ok) glfwTerminate();
  }
  bool ok;
};

bool same_box(const TankBounds& a, const TankBounds& b) {
  return a.min.x == b.min.x && a.min.y == b.min.y && a.min.z == b.min.z && a.max.x == b.max.x &&
         a.max.y == b.max.y && a.max.z == b.max.z;
}

// Mesa's software renderer (llvmpipe, e.g. under Xvfb) mallocs and frees
// megabytes of vertex data every frame; glibc would give it back to the kernel
// and page-fault it in again each frame. A GPU driver is unaffected.
void keep_freed_memory() {
#ifdef __GLIBC__
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
  mallopt(M_MMAP_THRESHOLD, 32 << 20);  // the largest glibc accepts on 64-bit
#endif
}

void on_glfw_error(int code, const char* description) {
  std::fprintf(stderr, "fishtank-viewer: GLFW error %d: %s\n", code, description);
}

class FullscreenToggle {
 public:
  explicit FullscreenToggle(GLFWwindow* window) : window_(window) {}
  void toggle() {
    if (glfwGetWindowMonitor(window_)) {
      glfwSetWindowMonitor(window_, nullptr, x_, y_, kWindowWidth, kWindowHeight, 0);
      return;
    }
    GLFWmonitor* monitor = glfwGetPrimaryMonitor();
    if (!monitor) return;
    glfwGetWindowPos(window_, &x_, &y_);
    const GLFWvidmode* mode = glfwGetVideoMode(monitor);
    glfwSetWindowMonitor(window_, monitor, 0, 0, mode->width, mode->height, mode->refreshRate);
  }

 private:
  GLFWwindow* window_;
  int x_ = 40, y_ = 40;  // where the window returns to
};

// The terminal hears of each new reason that no connection is made once, not at every retry.
void report_connection(const ConnectionStatus& s, const std::string& advice, std::string& reported) {
  if (s.state == ConnectionStatus::State::connected) {
    if (!reported.empty()) std::fprintf(stderr, "fishtank-viewer: connected to %s\n", s.endpoint.c_str());
    reported.clear();
    return;
  }
  if (s.last_error.empty() || s.last_error == reported) return;
  reported = s.last_error;
  std::fprintf(stderr, "fishtank-viewer: no connection to %s: %s; retrying every second.%s%s\n",
               s.endpoint.c_str(), s.last_error.c_str(), advice.empty() ? "" : " ", advice.c_str());
}

// The exit summary: the rates of the frames that drew the scene, or, when none
// did, the frames drawn while waiting and why nothing came.
void print_summary(const FrameStats& stats, const ConnectionStatus& s, std::uint32_t balls) {
  const auto rate = [](std::uint64_t frames, double seconds) {
    return seconds > 0.0 ? (frames - 1) / seconds : 0.0;
  };
  if (stats.total_frames() == 0) {
    std::fprintf(
        stderr,
        "fishtank-viewer: %llu frames in %.2f s (%.1f fps), none with the scene: no snapshot from %s%s%s\n",
        static_cast<unsigned long long>(stats.all_frames()), stats.all_seconds(),
        rate(stats.all_frames(), stats.all_seconds()), s.endpoint.c_str(), s.last_error.empty() ? "" : ": ",
        s.last_error.c_str());
    return;
  }
  const std::uint64_t waiting = stats.all_frames() - stats.total_frames();
  std::fprintf(
      stderr, "fishtank-viewer: %llu frames in %.2f s (%.1f fps), %.3f ms CPU per frame outside GL, %u balls",
      static_cast<unsigned long long>(stats.total_frames()), stats.total_seconds(),
      rate(stats.total_frames(), stats.total_seconds()), stats.mean_cpu_ms(), balls);
  if (waiting > 0)
    std::fprintf(stderr, "; before them %llu frames waiting for the server",
                 static_cast<unsigned long long>(waiting));
  if (stats.minimised_seconds() > 0.0)
    std::fprintf(stderr, "; %.1f s minimised, not counted", stats.minimised_seconds());
  std::fprintf(stderr, "\n");
}

}  // namespace

int run_viewer(const ViewerOptions& opt) {
  keep_freed_memory();
  glfwSetErrorCallback(on_glfw_error);
  GlfwSession glfw;
  if (!glfw.ok) {
    std::fprintf(
        stderr,
        "fishtank-viewer: cannot open the display (is DISPLAY set?); without one, run it under xvfb-run, "
        "or open the server's browser viewer (the 'web viewer on' line of its log)\n");
    return 1;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);  // SPEC 5.2: 1280x1024 or full screen
  const std::string title = "Fishtank - " + host_port_text(opt.host, opt.port);
  GLFWwindow* window = glfwCreateWindow(kWindowWidth, kWindowHeight, title.c_str(), nullptr, nullptr);
  if (!window) {
    std::fprintf(stderr, "fishtank-viewer: cannot create a 1280x1024 OpenGL 3.3 core window\n");
    return 1;
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);
  glewExperimental = GL_TRUE;  // core profiles need it for GLEW 2.x to load every entry point
  if (GLenum err = glewInit(); err != GLEW_OK) {
    std::fprintf(stderr, "fishtank-viewer: GLEW: %s\n",
                 reinterpret_cast<const char*>(glewGetErrorString(err)));
    return 1;
  }
  // The swap interval does nothing under Xvfb, so a cap of our own keeps a CPU
  // renderer from drawing flat out on the cores it shares with the server.
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  FramePacer pacer(choose_max_fps(opt.max_fps, renderer));
  const std::string cap =
      pacer.max_fps() > 0 ? "frames capped at " + std::to_string(pacer.max_fps()) + "/s" : "frames uncapped";
  std::fprintf(stderr, "fishtank-viewer: %s (%s): %s; --max-fps changes it\n",
               is_software_renderer(renderer) ? "software OpenGL" : "OpenGL", renderer ? renderer : "unknown",
               cap.c_str());
  FullscreenToggle fullscreen(window);
  if (opt.fullscreen) fullscreen.toggle();

  int exit_code = 0;
  bool screenshot_tried = false;  // --screenshot saved, failed or timed out: each says so
  {
    // Scope: every GL object is destroyed while the context still exists.
    Input input(window);
    Hud hud(window);
    SphereRenderer spheres;
    TankOutline tank_outline;
    SnapshotBuffer snapshots;
    NetClient net(opt.host, opt.port, !opt.observer, snapshots);
    OrbitCamera camera;
    camera.frame(TankBounds{});
    FrameStats stats;
    LivePlots plots;
    std::string viewer_notice;
    double viewer_notice_time = -1.0;

    glEnable(GL_DEPTH_TEST);
    glEnable(GL_CULL_FACE);
    glClearColor(0.055f, 0.066f, 0.09f, 1.0f);

    bool show_tank = opt.tank_outline, show_help = false, show_stats = opt.hud, show_plots = opt.hud;
    std::vector<SphereInstance> instances;
    TankBounds framed;  // the camera frames the tank again only if a server's tank differs
    int frames_since_snapshot = 0;
    std::string reported_error;
    const double started = steady_seconds();
    bool was_minimised = false;
    double minimised_at = 0.0;

    while (!glfwWindowShouldClose(window)) {
      glfwPollEvents();
      const double frame_start = steady_seconds();
      const double cpu_start = thread_cpu_seconds();

      Actions a = input.take_actions();
      if (a.quit || (opt.duration > 0.0 && frame_start - started >= opt.duration))
        glfwSetWindowShouldClose(window, GLFW_TRUE);
      if (a.toggle_tank) show_tank = !show_tank;
      if (a.toggle_help) show_help = !show_help;
      if (a.toggle_hud) show_stats = !show_stats;
      if (a.toggle_fullscreen) fullscreen.toggle();
      if (a.toggle_plots) show_plots = !show_plots;
      if (a.add_balls) net.add_balls(kBallsPerPress);
      const std::shared_ptr<const Snapshot> newest = snapshots.newest();
      for (protocol::Frame& frame : sandbox_frames(a.sandbox, newest.get()))
        net.send_command(std::move(frame));
      if (newest) plots.add(*newest);

      input.drive_camera(camera);
      if (!opt.observer) net.set_velocity(input.movement(camera) * kPlayerSpeed);
      // A minimised window draws nothing: it asks for no snapshots and waits for events instead.
      const bool minimised = glfwGetWindowAttrib(window, GLFW_ICONIFIED) != 0;
      if (minimised != was_minimised) {
        net.set_watching(!minimised);
        if (minimised)
          minimised_at = frame_start;
        else
          stats.not_drawn(minimised_at, frame_start);
      }
      was_minimised = minimised;
      if (minimised) {
        glfwWaitEventsTimeout(0.25);
        continue;
      }

      // The pair first, then the status: a snapshot of a new connection is
      // only ever pushed after that connection's status (and ball kinds).
      RenderPair pair;
      const bool have_frame = snapshots.frame_at(frame_start, pair);
      const ConnectionStatus status = net.status();
      const std::string advice = connection_advice(opt.host, opt.port, status.last_error);
      report_connection(status, advice, reported_error);
      int own = -1;
      instances.clear();
      if (have_frame && status.info) {
        const TankBounds& tank = pair.to->tank;
        if (!same_box(framed, tank)) {
          camera.frame(tank);
          tank_outline.set_bounds(tank);
          framed = tank;
        }
        own = interpolate(pair, *status.info, instances);
      }

      HudView view;
      view.fps = stats.fps();
      view.frame_ms = stats.frame_ms();
      view.cpu_ms = stats.cpu_ms();
      view.net = &status;
      view.connection_advice = advice;
      view.snapshot = newest.get();
      view.render_delay_ms = static_cast<float>(1e3 * snapshots.render_delay());
      view.observer = opt.observer;
      view.show_stats = show_stats;
      view.show_help = show_help;
      view.show_plots = show_plots;
      view.plots = &plots;
      view.viewer_notice = viewer_notice;
      view.viewer_notice_time = viewer_notice_time;
      view.now = frame_start;
      hud.build(view);
      const double cpu_seconds = thread_cpu_seconds() - cpu_start;

      int width = 0, height = 0;
      glfwGetFramebufferSize(window, &width, &height);
      glViewport(0, 0, width, height);
      glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
      const Mat4 view_proj = camera.view_projection(height > 0 ? static_cast<float>(width) / height : 1.0f);
      spheres.draw(view_proj, instances);
      if (own >= 0) {
        SphereInstance mine = instances[static_cast<std::size_t>(own)];
        mine.rgba = kOutlineRgba;
        float scale = 1.0f;  // the desktop's scale factor (HiDPI): 8 pixels at 100 %, 12 at 150 %
        glfwGetWindowContentScale(window, nullptr, &scale);
        const float grow =
            outline_grow(radius_on_screen(view_proj, {mine.x, mine.y, mine.z}, mine.radius, float(height)),
                         kOutlineMinPixels * scale, kOutlineGrow);
        spheres.draw_outline(view_proj, mine, grow);
        spheres.draw_hidden(view_proj, mine, grow, kHiddenAlpha);
      }
      if (show_tank) tank_outline.draw(view_proj);
      hud.render();
      if (a.screenshot) {
        const std::string path = new_screenshot_path();
        viewer_notice = save_screenshot(path, width, height) ? "screenshot saved: " + path
                                                             : "could not save a screenshot at " + path;
        viewer_notice_time = frame_start;
        std::fprintf(stderr, "fishtank-viewer: %s\n", viewer_notice.c_str());
      }

      if (!opt.screenshot.empty()) {
        if (have_frame && ++frames_since_snapshot >= opt.frames) {
          if (!save_screenshot(opt.screenshot, width, height)) exit_code = 1;
          screenshot_tried = true;
          glfwSetWindowShouldClose(window, GLFW_TRUE);
        } else if (!have_frame && frame_start - started > opt.screenshot_timeout) {
          std::fprintf(stderr, "fishtank-viewer: no snapshot from %s within %.0f s: %s\n",
                       status.endpoint.c_str(), opt.screenshot_timeout, status.last_error.c_str());
          exit_code = 1;
          screenshot_tried = true;
          glfwSetWindowShouldClose(window, GLFW_TRUE);
        }
      }
      glfwSwapBuffers(window);
      stats.frame_done(steady_seconds(), cpu_seconds, have_frame);
      if (const double sleep = pacer.sleep_seconds(steady_seconds()); sleep > 0.0)
        std::this_thread::sleep_for(std::chrono::duration<double>(sleep));
    }

    const std::shared_ptr<const Snapshot> last = snapshots.newest();
    print_summary(stats, net.status(), last ? last->ball_count : 0u);
    // Closed first (--duration, the window): a script waiting for the file must not read success.
    if (!opt.screenshot.empty() && !screenshot_tried) {
      std::fprintf(stderr, "fishtank-viewer: --screenshot %s not saved: the viewer closed before %s\n",
                   opt.screenshot.c_str(),
                   stats.total_frames() > 0 ? "its --frames were drawn" : "the first snapshot came");
      exit_code = 1;
    }
  }
  glfwDestroyWindow(window);
  return exit_code;
}

}  // namespace fishtank::viewer
