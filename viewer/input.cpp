#include "viewer/input.h"

#include <GLFW/glfw3.h>
#include <imgui.h>

namespace fishtank::viewer {

Input::Input(GLFWwindow* window) : window_(window) {
  glfwSetWindowUserPointer(window, this);
  glfwSetKeyCallback(window, on_key);
  glfwSetScrollCallback(window, on_scroll);
}

void Input::on_key(GLFWwindow* window, int key, int, int action, int) {
  if (action != GLFW_PRESS) return;
  auto* self = static_cast<Input*>(glfwGetWindowUserPointer(window));
  Actions& a = self->pending_;
  switch (key) {
    case GLFW_KEY_T:
      a.toggle_tank = true;
      break;
    case GLFW_KEY_H:
      a.toggle_help = true;
      break;
    case GLFW_KEY_F1:
      a.toggle_hud = true;
      break;
    case GLFW_KEY_B:
      a.add_balls = true;
      break;
    case GLFW_KEY_F11:
      a.toggle_fullscreen = true;
      break;
    case GLFW_KEY_F2:
      a.toggle_plots = true;
      break;
    case GLFW_KEY_F12:
      a.screenshot = true;
      break;
    case GLFW_KEY_ESCAPE:
      a.quit = true;
      break;
    case GLFW_KEY_P:
      a.sandbox.toggle_pause = true;
      break;
    case GLFW_KEY_O:
      a.sandbox.single_step = true;
      break;
    case GLFW_KEY_R:
      a.sandbox.reset = true;
      break;
    case GLFW_KEY_LEFT_BRACKET:
      a.sandbox.time_scale_change = -1;
      break;
    case GLFW_KEY_RIGHT_BRACKET:
      a.sandbox.time_scale_change = +1;
      break;
    case GLFW_KEY_1:
    case GLFW_KEY_2:
    case GLFW_KEY_3:
    case GLFW_KEY_4:
      a.sandbox.scene = key - GLFW_KEY_1;
      break;
    default:
      break;
  }
}

void Input::on_scroll(GLFWwindow* window, double, double dy) {
  if (ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureMouse) return;
  static_cast<Input*>(glfwGetWindowUserPointer(window))->scroll_ += static_cast<float>(dy);
}

Actions Input::take_actions() {
  Actions a = pending_;
  pending_ = {};
  return a;
}

bool Input::held(int key) const { return glfwGetKey(window_, key) == GLFW_PRESS; }

Vec3 Input::movement(const OrbitCamera& camera) const {
  Vec3 f = camera.forward_on_ground();
  Vec3 r = camera.right_on_ground();
  Vec3 d;
  if (held(GLFW_KEY_W)) d = d + f;
  if (held(GLFW_KEY_S)) d = d - f;
  if (held(GLFW_KEY_D)) d = d + r;
  if (held(GLFW_KEY_A)) d = d - r;
  if (held(GLFW_KEY_E) || held(GLFW_KEY_SPACE)) d.y += 1.0f;
  if (held(GLFW_KEY_Q) || held(GLFW_KEY_LEFT_SHIFT) || held(GLFW_KEY_RIGHT_SHIFT)) d.y -= 1.0f;
  return normalize(d);  // diagonals no faster than straight moves
}

void Input::drive_camera(OrbitCamera& camera) {
  double x = 0.0, y = 0.0;
  glfwGetCursorPos(window_, &x, &y);
  const bool down = glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
  // A drag belongs to the camera only if it started outside the HUD.
  if (down && !dragging_) dragging_ = !ImGui::GetIO().WantCaptureMouse;
  if (!down) dragging_ = false;
  if (dragging_) camera.orbit(static_cast<float>(x - last_x_), static_cast<float>(y - last_y_));
  last_x_ = x;
  last_y_ = y;
  if (scroll_ != 0.0f) camera.zoom(scroll_);
  scroll_ = 0.0f;
}

}  // namespace fishtank::viewer
