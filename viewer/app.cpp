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

#include "common/cpu_clock.h"
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
  FullscreenToggle(GLFWwindow* window, bool full_screen) : window_(window) {
    if (full_screen) toggle();
  }
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

// Opens the 1280x1024 OpenGL 3.3 core window (full screen with --fullscreen, later) and loads GL's entry
// points; nullptr, having said why, where it cannot.
GLFWwindow* open_window(const ViewerOptions& opt) {
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);  // SPEC 5.2: 1280x1024 or full screen
  const std::string title = "Fishtank - " + host_port_text(opt.host, opt.port);
  GLFWwindow* window = glfwCreateWindow(kWindowWidth, kWindowHeight, title.c_str(), nullptr, nullptr);
  if (!window) {
    std::fprintf(stderr, "fishtank-viewer: cannot create a 1280x1024 OpenGL 3.3 core window\n");
    return nullptr;
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);
  glewExperimental = GL_TRUE;  // core profiles need it for GLEW 2.x to load every entry point
  if (GLenum err = glewInit(); err != GLEW_OK) {
    std::fprintf(stderr, "fishtank-viewer: GLEW: %s\n",
                 reinterpret_cast<const char*>(glewGetErrorString(err)));
    glfwDestroyWindow(window);
    return nullptr;
  }
  return window;
}

// The swap interval does nothing under Xvfb, so a cap of our own keeps a CPU
// renderer from drawing flat out on the cores it shares with the server.
FramePacer announced_pacer(const ViewerOptions& opt) {
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  FramePacer pacer(choose_max_fps(opt.max_fps, renderer));
  const std::string cap =
      pacer.max_fps() > 0 ? "frames capped at " + std::to_string(pacer.max_fps()) + "/s" : "frames uncapped";
  std::fprintf(stderr, "fishtank-viewer: %s (%s): %s; --max-fps changes it\n",
               is_software_renderer(renderer) ? "software OpenGL" : "OpenGL", renderer ? renderer : "unknown",
               cap.c_str());
  return pacer;
}

// One window's frames, in the order app.h draws them. Its GL objects are made
// and destroyed while the window's context exists.
class Viewer {
 public:
  Viewer(GLFWwindow* window, const ViewerOptions& opt)
      : opt_(opt),
        window_(window),
        pacer_(announced_pacer(opt)),
        fullscreen_(window, opt.fullscreen),  // before the HUD and input are made, as the window they see
        input_(window),
        hud_(window),
        net_(opt.host, opt.port, !opt.observer, snapshots_) {
    camera_.frame(TankBounds{});
    glEnable(GL_DEPTH_TEST);
    glEnable(GL_CULL_FACE);
    glClearColor(0.055f, 0.066f, 0.09f, 1.0f);
  }

  // Frames until the window closes; the process exit code.
  int run() {
    while (!glfwWindowShouldClose(window_)) frame();
    const std::shared_ptr<const Snapshot> last = snapshots_.newest();
    print_summary(stats_, net_.status(), last ? last->ball_count : 0u);
    // Closed first (--duration, the window): a script waiting for the file must not read success.
    if (!opt_.screenshot.empty() && !screenshot_tried_) {
      std::fprintf(stderr, "fishtank-viewer: --screenshot %s not saved: the viewer closed before %s\n",
                   opt_.screenshot.c_str(),
                   stats_.total_frames() > 0 ? "its --frames were drawn" : "the first snapshot came");
      exit_code_ = 1;
    }
    return exit_code_;
  }

 private:
  void frame() {
    glfwPollEvents();
    const double now = steady_seconds();
    const double cpu_start = thread_cpu_seconds();
    const std::shared_ptr<const Snapshot> newest = snapshots_.newest();
    const Actions actions = take_input(now, newest.get());
    if (minimised(now)) {
      glfwWaitEventsTimeout(0.25);
      return;
    }

    // The pair first, then the status: a snapshot of a new connection is
    // only ever pushed after that connection's status (and ball kinds).
    RenderPair pair;
    const bool have_frame = snapshots_.frame_at(now, pair);
    const ConnectionStatus status = net_.status();
    const std::string advice = connection_advice(opt_.host, opt_.port, status.last_error);
    report_connection(status, advice, reported_error_);
    instances_.clear();
    const int own = have_frame && status.info ? place_balls(pair, *status.info) : -1;
    build_hud(now, status, advice, newest.get());
    const double cpu_seconds = thread_cpu_seconds() - cpu_start;

    int width = 0, height = 0;
    glfwGetFramebufferSize(window_, &width, &height);
    draw(width, height, own);
    if (actions.screenshot) save_typed_screenshot(now, width, height);
    if (!opt_.screenshot.empty()) screenshot_option(now, have_frame, status, width, height);
    glfwSwapBuffers(window_);
    stats_.frame_done(steady_seconds(), cpu_seconds, have_frame);
    if (const double sleep = pacer_.sleep_seconds(steady_seconds()); sleep > 0.0)
      std::this_thread::sleep_for(std::chrono::duration<double>(sleep));
  }

  // Keys, the mouse and the player's stick; the sandbox's commands go to the server.
  Actions take_input(double now, const Snapshot* newest) {
    const Actions a = input_.take_actions();
    if (a.quit || (opt_.duration > 0.0 && now - started_ >= opt_.duration))
      glfwSetWindowShouldClose(window_, GLFW_TRUE);
    if (a.toggle_tank) show_tank_ = !show_tank_;
    if (a.toggle_help) show_help_ = !show_help_;
    if (a.toggle_hud) show_stats_ = !show_stats_;
    if (a.toggle_fullscreen) fullscreen_.toggle();
    if (a.toggle_plots) show_plots_ = !show_plots_;
    if (a.add_balls) net_.add_balls(kBallsPerPress);
    for (protocol::Frame& frame : sandbox_frames(a.sandbox, newest)) net_.send_command(std::move(frame));
    if (newest) plots_.add(*newest);
    input_.drive_camera(camera_);
    if (!opt_.observer) net_.set_velocity(input_.movement(camera_) * kPlayerSpeed);
    return a;
  }

  // A minimised window draws nothing: it asks for no snapshots and waits for events instead.
  bool minimised(double now) {
    const bool minimised = glfwGetWindowAttrib(window_, GLFW_ICONIFIED) != 0;
    if (minimised != was_minimised_) {
      net_.set_watching(!minimised);
      if (minimised)
        minimised_at_ = now;
      else
        stats_.not_drawn(minimised_at_, now);
    }
    was_minimised_ = minimised;
    return minimised;
  }

  // This frame's spheres, between the pair's snapshots; the index of our own, or -1.
  int place_balls(const RenderPair& pair, const ServerInfo& info) {
    const TankBounds& tank = pair.to->tank;
    if (!same_box(framed_, tank)) {
      camera_.frame(tank);
      tank_outline_.set_bounds(tank);
      framed_ = tank;
    }
    return interpolate(pair, info, instances_);
  }

  void build_hud(double now, const ConnectionStatus& status, const std::string& advice,
                 const Snapshot* newest) {
    HudView view;
    view.fps = stats_.fps();
    view.frame_ms = stats_.frame_ms();
    view.cpu_ms = stats_.cpu_ms();
    view.net = &status;
    view.connection_advice = advice;
    view.snapshot = newest;
    view.render_delay_ms = static_cast<float>(1e3 * snapshots_.render_delay());
    view.observer = opt_.observer;
    view.show_stats = show_stats_;
    view.show_help = show_help_;
    view.show_plots = show_plots_;
    view.plots = &plots_;
    view.viewer_notice = notice_;
    view.viewer_notice_time = notice_time_;
    view.now = now;
    hud_.build(view);
  }

  void draw(int width, int height, int own) {
    glViewport(0, 0, width, height);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    const Mat4 view_proj = camera_.view_projection(height > 0 ? static_cast<float>(width) / height : 1.0f);
    spheres_.draw(view_proj, instances_);
    if (own >= 0) draw_own_ring(view_proj, instances_[static_cast<std::size_t>(own)], height);
    if (show_tank_) tank_outline_.draw(view_proj);
    hud_.render();
  }

  // Our own sphere in an amber ring, seen through the balls in front of it.
  void draw_own_ring(const Mat4& view_proj, SphereInstance mine, int height) {
    mine.rgba = kOutlineRgba;
    float scale = 1.0f;  // the desktop's scale factor (HiDPI): 8 pixels at 100 %, 12 at 150 %
    glfwGetWindowContentScale(window_, nullptr, &scale);
    const float grow =
        outline_grow(radius_on_screen(view_proj, {mine.x, mine.y, mine.z}, mine.radius, float(height)),
                     kOutlineMinPixels * scale, kOutlineGrow);
    spheres_.draw_outline(view_proj, mine, grow);
    spheres_.draw_hidden(view_proj, mine, grow, kHiddenAlpha);
  }

  // F12: a new file each time, and a notice on screen and in the terminal.
  void save_typed_screenshot(double now, int width, int height) {
    const std::string path = new_screenshot_path();
    notice_ = save_screenshot(path, width, height) ? "screenshot saved: " + path
                                                   : "could not save a screenshot at " + path;
    notice_time_ = now;
    std::fprintf(stderr, "fishtank-viewer: %s\n", notice_.c_str());
  }

  // --screenshot: saved after --frames frames with the scene, then the viewer closes; or it gives up.
  void screenshot_option(double now, bool have_frame, const ConnectionStatus& status, int width, int height) {
    if (have_frame && ++frames_since_snapshot_ >= opt_.frames) {
      if (!save_screenshot(opt_.screenshot, width, height)) exit_code_ = 1;
    } else if (!have_frame && now - started_ > opt_.screenshot_timeout) {
      std::fprintf(stderr, "fishtank-viewer: no snapshot from %s within %.0f s: %s\n",
                   status.endpoint.c_str(), opt_.screenshot_timeout, status.last_error.c_str());
      exit_code_ = 1;
    } else {
      return;
    }
    screenshot_tried_ = true;  // saved, failed or timed out: each says so
    glfwSetWindowShouldClose(window_, GLFW_TRUE);
  }

  const ViewerOptions& opt_;
  GLFWwindow* window_;
  FramePacer pacer_;
  FullscreenToggle fullscreen_;
  Input input_;  // before the HUD, whose ImGui chains to its callbacks
  Hud hud_;
  SphereRenderer spheres_;
  TankOutline tank_outline_;
  SnapshotBuffer snapshots_;
  NetClient net_;  // after the buffer it fills, and so stopped before it goes
  OrbitCamera camera_;
  FrameStats stats_;
  LivePlots plots_;
  bool show_tank_ = opt_.tank_outline, show_help_ = false, show_stats_ = opt_.hud, show_plots_ = opt_.hud;
  std::string
      notice_;  // the viewer's own news (a screenshot saved), shown for a few seconds from notice_time_
  double notice_time_ = -1.0;
  std::vector<SphereInstance> instances_;
  TankBounds framed_;  // the camera frames the tank again only if a server's tank differs
  int frames_since_snapshot_ = 0;
  std::string reported_error_;
  const double started_ = steady_seconds();
  bool was_minimised_ = false;
  double minimised_at_ = 0.0;
  int exit_code_ = 0;
  bool screenshot_tried_ = false;
};

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
  GLFWwindow* window = open_window(opt);
  if (!window) return 1;
  int exit_code = 0;
  {
    Viewer viewer(window, opt);  // destroyed, with its GL objects, while the context exists
    exit_code = viewer.run();
  }
  glfwDestroyWindow(window);
  return exit_code;
}

}  // namespace fishtank::viewer
