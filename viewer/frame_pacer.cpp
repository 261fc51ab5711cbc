#include "viewer/frame_pacer.h"

#include <cstring>

namespace fishtank::viewer {

bool is_software_renderer(const char* gl_renderer) {
  return gl_renderer && (std::strstr(gl_renderer, "llvmpipe") || std::strstr(gl_renderer, "softpipe"));
}

int choose_max_fps(int requested, const char* gl_renderer) {
  if (requested >= 0) return requested;
  return is_software_renderer(gl_renderer) ? kSoftwareMaxFps : kDefaultMaxFps;
}

FramePacer::FramePacer(int max_fps) : max_fps_(max_fps), interval_(max_fps > 0 ? 1.0 / max_fps : 0.0) {}

double FramePacer::sleep_seconds(double now) {
  if (max_fps_ <= 0) return 0.0;
  // Due times advance by whole intervals from the previous due time, not from
  // when the sleep ended, so oversleeping by a little does not slow the rate.
  // The first frame's start is unknown: the schedule starts at its end.
  due_ = started_ ? due_ + interval_ : now;
  started_ = true;
  if (due_ <= now) {
    // Late: start the schedule again from now rather than rushing frames
    // out to make up for the slow one.
    due_ = now;
    return 0.0;
  }
  return due_ - now;
}

}  // namespace fishtank::viewer
