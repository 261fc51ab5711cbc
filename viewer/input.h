#pragma once
// Keyboard and mouse: held keys become the player's velocity, key presses
// become one-shot actions, mouse drag and wheel move the camera. Input that
// falls on the HUD belongs to Dear ImGui.

#include "viewer/render/camera.h"
#include "viewer/sandbox_controls.h"

struct GLFWwindow;

namespace fishtank::viewer {

// Key presses since the last take_actions().
struct Actions {
  bool toggle_tank = false;        // T
  bool toggle_help = false;        // H
  bool toggle_hud = false;         // F1
  bool add_balls = false;          // B
  bool toggle_fullscreen = false;  // F11
  bool toggle_plots = false;       // F2
  bool screenshot = false;         // F12
  bool quit = false;               // Esc
  SandboxKeys sandbox;             // P, O, R, [, ], 1-4
};

class Input {
 public:
  // Installs key and scroll callbacks. Call before ImGui_ImplGlfw_InitForOpenGL,
  // which then chains to them.
  explicit Input(GLFWwindow* window);

  Actions take_actions();
  // Unit direction (or zero) from the held movement keys, relative to the
  // camera on the ground plane: W/S forward/back, A/D left/right,
  // E or Space up, Q or Shift down.
  Vec3 movement(const OrbitCamera& camera) const;
  // Left-button drag orbits, the wheel zooms.
  void drive_camera(OrbitCamera& camera);

 private:
  static void on_key(GLFWwindow* window, int key, int scancode, int action, int mods);
  static void on_scroll(GLFWwindow* window, double dx, double dy);
  bool held(int key) const;

  GLFWwindow* window_;
  Actions pending_;
  float scroll_ = 0.0f;
  bool dragging_ = false;
  double last_x_ = 0.0, last_y_ = 0.0;
};

}  // namespace fishtank::viewer
