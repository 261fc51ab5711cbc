#pragma once
// The heads-up display, drawn with Dear ImGui over the scene: measured frame
// and physics rates, the server's build, network figures, the connection's
// state, the sandbox's state (scene, paused, time scale, who may control),
// live plots of the last 30 s, and the help overlay with every control.

#include <cstdint>
#include <string>

#include "viewer/live_plots.h"
#include "viewer/net/client.h"

struct GLFWwindow;

namespace fishtank::viewer {

struct HudView {
  float fps = 0.0f;
  float frame_ms = 0.0f;
  float cpu_ms = 0.0f;  // per frame, outside GL calls
  const ConnectionStatus* net = nullptr;
  std::string connection_advice;       // what to do while no connection is made (connection_advice)
  const Snapshot* snapshot = nullptr;  // newest; null before the first
  float render_delay_ms = 0.0f;
  bool observer = false;
  bool show_stats = true;
  bool show_help = false;
  bool show_plots = true;
  LivePlots* plots = nullptr;
  std::string viewer_notice;  // the viewer's own news (a screenshot saved), shown for a few seconds
  double viewer_notice_time = -1.0;
  double now = 0.0;
};

class Hud {
 public:
  explicit Hud(GLFWwindow* window);  // after the GL context and Input exist
  ~Hud();
  Hud(const Hud&) = delete;
  Hud& operator=(const Hud&) = delete;

  void build(const HudView& view);  // CPU only: lays out this frame's widgets
  void render();                    // GL: draws them

 private:
  void stats(const HudView& v);
  void connection(const HudView& v);
  void help();
  void live_plots(const HudView& v);
};

}  // namespace fishtank::viewer
