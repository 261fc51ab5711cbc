#pragma once
// The viewer's frame cap: how long to sleep after a frame. Vsync cannot do it
// where Mesa renders on the CPU (Xvfb ignores the swap interval); pure, so tests need no clock.

namespace fishtank::viewer {

inline constexpr int kDefaultMaxFps = 60;
// Software renderers draw on the CPU, on the same cores the server steps on.
inline constexpr int kSoftwareMaxFps = 30;

// Whether GL_RENDERER names one of Mesa's CPU renderers (llvmpipe, softpipe).
bool is_software_renderer(const char* gl_renderer);

// The cap to use: `requested` when given (>= 0), else the default for the renderer.
int choose_max_fps(int requested, const char* gl_renderer);

class FramePacer {
 public:
  static constexpr int kMaxFps = 1000;  // the most --max-fps accepts

  // max_fps 0: uncapped, never sleeps.
  explicit FramePacer(int max_fps);

  // At the end of each frame, with the steady time now in seconds: the
  // seconds to sleep before the next frame starts, 0 when it is due already.
  double sleep_seconds(double now);

  int max_fps() const { return max_fps_; }

 private:
  int max_fps_;
  double interval_;
  double due_ = 0.0;  // when the next frame may start
  bool started_ = false;
};

}  // namespace fishtank::viewer
