#include "viewer/hud.h"

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <cfloat>
#include <cstdarg>
#include <cstdio>

#include "viewer/hud_text.h"

namespace fishtank::viewer {
namespace {

// Debian's fonts-dejavu-core (scripts/install-deps viewer). ImGui's built-in
// font is drawn for 13 pixels and small on a 1280x1024 screen; it is the
// fallback where DejaVu is missing.
constexpr const char* kFontPath = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
constexpr float kFontPixels = 17.0f;
constexpr double kNoticeSeconds = 6.0;

const ImVec4 kDim{0.65f, 0.70f, 0.78f, 1.0f};
const ImVec4 kWarn{1.0f, 0.55f, 0.35f, 1.0f};
const ImVec4 kStale{0.45f, 0.45f, 0.45f, 1.0f};

// live false: label and figure both greyed, the figure being left over from a lost connection.
void row(bool live, const char* label, const char* fmt, ...) IM_FMTARGS(3);
void row(bool live, const char* label, const char* fmt, ...) {
  ImGui::TextColored(live ? kDim : kStale, "%s", label);
  ImGui::SameLine(110.0f);
  if (!live) ImGui::PushStyleColor(ImGuiCol_Text, kStale);
  va_list args;
  va_start(args, fmt);
  ImGui::TextV(fmt, args);
  va_end(args);
  if (!live) ImGui::PopStyleColor();
}

}  // namespace

Hud::Hud(GLFWwindow* window) {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // no imgui.ini next to wherever the viewer was started
  if (std::FILE* f = std::fopen(kFontPath, "rb")) {
    std::fclose(f);
    io.Fonts->AddFontFromFileTTF(kFontPath, kFontPixels);
  } else {
    io.FontGlobalScale = 1.3f;
  }
  ImGui::StyleColorsDark();
  ImGui::GetStyle().WindowRounding = 4.0f;
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");
}

Hud::~Hud() {
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
}

void Hud::build(const HudView& v) {
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  if (v.show_stats) stats(v);
  if (v.show_plots && v.plots) live_plots(v);
  connection(v);
  if (v.show_help) help();
  ImGui::Render();
}

void Hud::render() { ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData()); }

void Hud::stats(const HudView& v) {
  const ConnectionStatus& net = *v.net;
  ImGui::SetNextWindowPos({12.0f, 12.0f});
  ImGui::SetNextWindowBgAlpha(0.55f);
  ImGui::Begin("stats", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                   ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoMove);
  // The viewer's own figures stay live; everything the server or the link reported greys when the link drops.
  row(true, "Frames", "%.1f fps   %.2f ms/frame", v.fps, v.frame_ms);
  row(true, "CPU", "%.2f ms/frame outside GL", v.cpu_ms);
  const Snapshot* s = v.snapshot;
  const Freshness fresh =
      figures_freshness(net.state == ConnectionStatus::State::connected, v.now, s ? s->received : -1.0);
  const bool live = fresh.live;
  if (s) {
    row(live, "Physics", "%.0f steps/s   load %.0f %%", s->steps_per_s, 100.0f * s->load);
    row(live, "Time", "%s", time_scale_text(s->time_scale, s->time_scale_set, s->paused).c_str());
    row(live, "Scene", "%s (start %u)", s->scene.empty() ? "-" : s->scene.c_str(), s->scene_start);
    row(live, "Balls", "%u", s->ball_count);
    const OverlapText overlap = overlap_text(s->max_overlap, s->kinetic_energy_per_ball);
    if (overlap.warn && live) {
      ImGui::TextColored(kDim, "Overlap");
      ImGui::SameLine(110.0f);
      ImGui::TextColored(kWarn, "%s", overlap.text.c_str());
    } else {
      row(live, "Overlap", "%s", overlap.text.c_str());
    }
  } else {
    row(live, "Physics", "-");
    row(live, "Time", "-");
    row(live, "Scene", "-");
    row(live, "Balls", "-");
    row(live, "Overlap", "-");
  }
  if (const ServerInfo* info = net.info.get()) {
    row(live, "Threads", "%s", threads_text(s ? s->threads_stepping : 0, info->threads).c_str());
    row(live, "Server", "%s (SIMD %s)", info->variant.c_str(), info->simd.c_str());
    row(live, "Step", "%s", step_text(info->dt, info->steps_per_contact, info->tolerance).c_str());
  } else {
    row(live, "Threads", "-");
    row(live, "Server", "%s", net.endpoint.c_str());
    row(live, "Step", "-");
  }
  row(live, "Snapshots", "%.1f /s   render delay %.0f ms", net.snapshots_per_s, v.render_delay_ms);
  // Bytes received, frames whole: with deltas a still pile costs a fraction of a byte per ball.
  if (s && s->ball_count > 0 && net.snapshots_per_s > 0.0f)
    row(live, "Bandwidth", "%.1f KiB/s in, %.2f B per ball", net.bytes_per_s / 1024.0f,
        net.bytes_per_s / (net.snapshots_per_s * static_cast<float>(s->ball_count)));
  else
    row(live, "Bandwidth", "%.1f KiB/s in", net.bytes_per_s / 1024.0f);
  if (net.rtt_ms >= 0.0f)
    row(live, "Round trip", "%.2f ms", net.rtt_ms);
  else
    row(live, "Round trip", "-");
  ImGui::PushTextWrapPos(520.0f);
  const ServerInfo* info = net.info.get();
  // Refused a sphere it asked for, or its sphere freed: the server said why, or where it waits.
  const bool refused = !v.observer && info && !info->has_player;
  if (refused && info->ahead_in_line)
    row(live, "Player", "%s", in_line_text(*info->ahead_in_line).c_str());
  else if (refused && !info->observing.empty())
    row(live, "Player", "observing: %s", info->observing.c_str());
  else if (v.observer || refused)
    row(live, "Player", "observing");
  else
    row(live, "Player", "yours is the white sphere with the amber ring");
  if (info) row(live, "Control", "%s", control_text(info->may_control, info->control_policy).c_str());
  ImGui::PopTextWrapPos();
  if (!live) ImGui::TextColored(kWarn, "%s", fresh.note.c_str());
  ImGui::TextColored(kDim, "H: help");
  if (!v.viewer_notice.empty() && v.now - v.viewer_notice_time < kNoticeSeconds) {
    ImGui::PushTextWrapPos(520.0f);
    ImGui::TextUnformatted(v.viewer_notice.c_str());
    ImGui::PopTextWrapPos();
  }
  if (!net.notice.empty() && v.now - net.notice_time < kNoticeSeconds) {
    ImGui::PushTextWrapPos(520.0f);
    ImGui::TextColored(kWarn, "%s", net.notice.c_str());
    ImGui::PopTextWrapPos();
  }
  ImGui::End();
}

void Hud::connection(const HudView& v) {
  const ConnectionStatus& net = *v.net;
  if (net.state == ConnectionStatus::State::connected) return;
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos({vp->WorkPos.x + vp->WorkSize.x * 0.5f, vp->WorkPos.y + vp->WorkSize.y * 0.4f},
                          ImGuiCond_Always, {0.5f, 0.5f});
  ImGui::SetNextWindowBgAlpha(0.8f);
  ImGui::Begin("connection", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoNav |
                   ImGuiWindowFlags_NoMove);
  ImGui::SetWindowFontScale(1.5f);
  if (net.state == ConnectionStatus::State::connecting && net.last_error.empty()) {
    ImGui::Text("Connecting to %s ...", net.endpoint.c_str());
  } else {
    ImGui::TextColored(kWarn, "No connection to the server at %s", net.endpoint.c_str());
    ImGui::SetWindowFontScale(1.0f);
    ImGui::Text("%s", net.last_error.c_str());
    ImGui::Text("Retrying every second (%d attempt%s so far).", net.attempts, net.attempts == 1 ? "" : "s");
    ImGui::Text("%s", v.connection_advice.c_str());
  }
  ImGui::End();
}

void Hud::live_plots(const HudView& v) {
  LivePlots& plots = *v.plots;
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos({vp->WorkPos.x + vp->WorkSize.x - 12.0f, 12.0f}, ImGuiCond_Always, {1.0f, 0.0f});
  ImGui::SetNextWindowBgAlpha(0.55f);
  ImGui::Begin("plots", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                   ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoMove);
  ImGui::TextColored(kDim, "Last %.0f s", plots.span_seconds());
  struct Plot {
    LivePlots::Series series;
    const char* format;  // of the newest value
  };
  static constexpr Plot kPlots[] = {{LivePlots::kinetic_energy, "kinetic energy %.3g J/ball"},
                                    {LivePlots::contacts, "contacts %.0f"},
                                    {LivePlots::steps_per_s, "steps/s %.0f"},
                                    {LivePlots::time_scale, "time scale %.2f"}};
  for (const Plot& p : kPlots) {
    char label[64];
    std::snprintf(label, sizeof label, p.format, plots.newest(p.series));
    const std::vector<float>& values = plots.series(p.series);
    ImGui::TextUnformatted(label);
    ImGui::PushID(p.series);
    // From zero up, so a plot's height compares with its own past.
    ImGui::PlotLines("", values.data(), static_cast<int>(values.size()), 0, nullptr, 0.0f, FLT_MAX,
                     {300.0f, 48.0f});
    ImGui::PopID();
  }
  ImGui::End();
}

void Hud::help() {
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos({vp->WorkPos.x + vp->WorkSize.x * 0.5f, vp->WorkPos.y + vp->WorkSize.y * 0.5f},
                          ImGuiCond_Always, {0.5f, 0.5f});
  ImGui::SetNextWindowBgAlpha(0.85f);
  ImGui::Begin("Controls", nullptr,
               ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoMove);
  static constexpr const char* kControls[][2] = {
      {"W / S", "move your sphere forward / back (away from / towards the camera)"},
      {"A / D", "move your sphere left / right"},
      {"E or Space", "move your sphere up"},
      {"Q or Shift", "move your sphere down"},
      {"Left-drag", "orbit the camera around the tank"},
      {"Wheel", "zoom in / out"},
      {"B", "pour 1000 more balls in from the top"},
      {"P", "pause / resume the simulation (for everyone)"},
      {"O", "one step (pauses first)"},
      {"R", "reset: the scene from its start"},
      {"[ / ]", "time scale slower / faster: 0.1, 0.25, 0.5, 1"},
      {"1 2 3 4", "scene: tank, wide, dam-break, drop"},
      {"", "(P O R [ ] 1-4 as the server's --control allows: see Control)"},
      {"F12", "save a screenshot (PNG) in the working folder"},
      {"F2", "show / hide the live plots"},
      {"T", "show / hide the tank's edges"},
      {"F1", "show / hide the statistics"},
      {"F11", "full screen on / off"},
      {"H", "show / hide this help"},
      {"Esc", "quit"},
  };
  for (const auto& c : kControls) {
    ImGui::TextColored(kDim, "%s", c[0]);
    ImGui::SameLine(130.0f);
    ImGui::TextUnformatted(c[1]);
  }
  ImGui::End();
}

}  // namespace fishtank::viewer
