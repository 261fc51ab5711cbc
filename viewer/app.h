#pragma once
// The viewer's main thread: the window, the frame loop, and the wiring of
// net client, interpolation, renderers, HUD and input.
//
// One frame (Viewer::frame):  poll input ► (minimised: wait for events) ► pick
// the snapshot pair for now ► interpolate into instances ► lay out the HUD
// ─ (CPU above, GL below) ─► draw spheres, the own sphere's ring, tank edges,
// HUD ► screenshots (F12, --screenshot) ► swap.

#include <string>

namespace fishtank::viewer {

struct ViewerOptions {
  std::string host = "127.0.0.1";
  std::string port = "7878";
  bool fullscreen = false;
  bool observer = false;  // no player sphere of our own
  bool hud = true;
  bool tank_outline = false;  // start with the tank's edges shown
  std::string screenshot;     // non-empty: save this PNG after `frames` frames, then exit
  int frames = 1;
  double screenshot_timeout = 30.0;  // seconds to wait for the first snapshot
  int max_fps = -1;                  // frames per second at most, 0 uncapped; -1: by renderer (frame_pacer.h)
  double duration = 0.0;             // seconds until the viewer closes itself; 0: until closed
};

// Returns the process exit code.
int run_viewer(const ViewerOptions& options);

}  // namespace fishtank::viewer
