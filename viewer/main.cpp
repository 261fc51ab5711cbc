// fishtank-viewer: flags, then the viewer's loop (viewer/app.cpp). Nothing else.

#include <boost/program_options.hpp>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>

#include "common/flag_values.h"
#include "common/host_port.h"
#include "common/number_text.h"
#include "common/output_paths.h"
#include "viewer/app.h"
#include "viewer/frame_pacer.h"

namespace po = boost::program_options;

int main(int argc, char** argv) {
  fishtank::viewer::ViewerOptions opt;
  std::string connect = fishtank::host_port_text(opt.host, opt.port);
  po::options_description flags(
      "fishtank-viewer: shows a fishtank-server's simulation and steers a player sphere in it.\n"
      "Usage: fishtank-viewer [--connect host:port] [--fullscreen] [--observer]\n"
      "Keys: H shows every control in the window.\n\nOptions");
  flags.add_options()                                                                                   //
      ("help,h", "print this help and exit")                                                            //
      ("connect", po::value(&connect), "server to connect to, host:port (default 127.0.0.1:7878)")      //
      ("fullscreen", po::bool_switch(&opt.fullscreen), "start in full screen (F11 toggles)")            //
      ("observer", po::bool_switch(&opt.observer), "watch only: no player sphere of our own")           //
      ("no-hud", "start with the statistics and live plots hidden (F1, F2 toggle)")                     //
      ("outline", po::bool_switch(&opt.tank_outline), "start with the tank's edges shown (T toggles)")  //
      ("screenshot", po::value(&opt.screenshot),
       "render --frames frames after the first snapshot, save the last "
       "as this PNG file and exit")                                                           //
      ("frames", po::value(&opt.frames), "frames to render before --screenshot (default 1)")  //
      ("max-fps", po::value(&opt.max_fps),
       "frames per second at most, 0 for no cap (default 60; 30 on a software renderer such as "
       "Mesa's llvmpipe, which shares the CPU with the server)")  //
      ("duration", po::value(&opt.duration),
       "close the viewer after this many seconds (default 0: stay open)");
  // Every bad flag: one line that says what is wrong, the pointer to --help, exit code 2.
  auto refuse = [](const std::string& why) {
    std::fprintf(stderr, "fishtank-viewer: %s\nTry --help for the list of options.\n", why.c_str());
    return 2;
  };
  po::variables_map vm;
  try {
    po::store(fishtank::parse_flags(argc, argv, flags), vm);
    po::notify(vm);
  } catch (const po::error& e) {
    return refuse(fishtank::flag_error_text(e, flags));
  }
  if (vm.count("help")) {
    std::cout << flags << "\n";
    return 0;
  }
  opt.hud = vm.count("no-hud") == 0;
  const auto address = fishtank::parse_host_port(connect);
  if (!address) return refuse("--connect wants host:port with a port 1 .. 65535, got '" + connect + "'");
  opt.host = address->host;
  opt.port = std::to_string(address->port);
  if (opt.frames < 1) return refuse("--frames must be at least 1, got " + std::to_string(opt.frames));
  if (vm.count("frames") && opt.screenshot.empty())
    return refuse("--frames counts the frames before --screenshot: give --screenshot FILE too, or drop it");
  if (!opt.screenshot.empty()) {
    const std::string& path = opt.screenshot;
    if (path.size() < 4 || path.compare(path.size() - 4, 4, ".png") != 0)
      return refuse("--screenshot writes a PNG: name a .png file, got '" + path + "'");
    if (const std::string why = fishtank::check_writable_file(path); !why.empty())
      return refuse("--screenshot " + path + ": " + why);
  }
  if (vm.count("max-fps") && (opt.max_fps < 0 || opt.max_fps > fishtank::viewer::FramePacer::kMaxFps))
    return refuse("--max-fps must be between 0 (no cap) and " +
                  std::to_string(fishtank::viewer::FramePacer::kMaxFps) + ", got " +
                  std::to_string(opt.max_fps));
  if (!std::isfinite(opt.duration) || opt.duration < 0.0 || opt.duration > 1e9)
    return refuse("--duration must be a number of seconds >= 0 (0: stay open), got " +
                  fishtank::number_text(opt.duration));
  return fishtank::viewer::run_viewer(opt);
}
