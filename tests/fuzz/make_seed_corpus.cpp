// Writes the fuzzer's seed corpus: one file per valid frame of every message
// type (and one stream of several), each preceded by the chunk-size byte that
// fuzz_frames.cpp reads first. Usage: make_seed_corpus DIRECTORY

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "protocol/frame_codec.h"

using namespace fishtank;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_seed_corpus DIRECTORY\n");
    return 2;
  }
  protocol::WelcomeInfo welcome;
  welcome.server_variant = "sse";
  welcome.simd_level = "sse4.1";
  welcome.dt = 0.000785f;
  welcome.player_id = 0;
  welcome.control_policy = "clients with a player sphere may pause";
  welcome.may_control = true;
  const std::uint16_t positions[9] = {0, 100, 65535, 32768, 0, 1, 2, 3, 4};
  const std::uint8_t kinds[3] = {0, 1, 2};
  const std::uint32_t player_ids[1] = {0};
  const Vec3 players[1] = {{0.0f, 20.0f, 0.0f}};
  protocol::SnapshotHeader header;
  header.tick = 5;
  header.sim_time = 1.25;
  header.scene = "tank";
  // The next snapshot as a delta against this one: one ball still, one moved, one new;
  // then one predicted from both (ball 0 falling).
  const std::uint16_t next[12] = {0, 100, 65535, 32769, 1, 0, 2, 3, 4, 7, 8, 9};
  const std::uint16_t third[12] = {0, 100, 65500, 32770, 1, 0, 2, 3, 4, 7, 8, 9};
  protocol::DeltaReference on_5{positions, 3, 5};
  protocol::DeltaReference on_6{next, 4, 6, positions, 3, 5};
  protocol::PositionsDelta delta, predicted;
  protocol::encode_positions_delta(on_5, 6, next, 4, delta);
  protocol::encode_positions_delta(on_6, 7, third, 4, predicted);
  protocol::SnapshotHeader next_header = header, third_header = header;
  next_header.tick = 6;
  third_header.tick = 7;

  const std::vector<std::pair<std::string, protocol::Frame>> frames = {
      {"hello", protocol::encode_hello("seed", true, true)},
      {"hello_observer", protocol::encode_hello("seed", false, false)},
      {"player_input", protocol::encode_player_input(1, {1.0f, -2.0f, 3.0f})},
      {"add_balls", protocol::encode_add_balls(1000)},
      {"ping", protocol::encode_ping(123456)},
      {"welcome", protocol::encode_welcome(welcome)},
      {"ball_kinds", protocol::encode_ball_kinds(0, kinds, 3)},
      {"snapshot", protocol::encode_snapshot(header, positions, 3, player_ids, players, 1)},
      {"error", protocol::encode_error(wire::ErrorCode::tank_full, "added 10 of 20 balls")},
      {"pong", protocol::encode_pong(123456)},
      {"pause", protocol::encode_pause(true)},
      {"step", protocol::encode_step(10)},
      {"reset", protocol::encode_reset("drop", 3)},
      {"set_time_scale", protocol::encode_set_time_scale(0.5f)},

      {"ack", protocol::encode_ack(5)},
      {"ack_keyframe", protocol::encode_ack(7, true)},
      {"delta_snapshot", protocol::encode_delta_snapshot(next_header, on_5, delta, 4, player_ids, players, 1)},
      {"predicted_snapshot", protocol::encode_delta_snapshot(third_header, on_6, predicted, 4, player_ids, players, 1)},
  };
  protocol::Frame conversation{0};  // chunk byte 0: one byte at a time
  for (const char* name : {"hello", "player_input", "add_balls", "ping", "pause", "step", "reset", "set_time_scale",
                           "ack", "ack_keyframe"})
    for (const auto& [n, f] : frames)
      if (n == name) conversation.insert(conversation.end(), f.begin(), f.end());
  // What a client reads: a keyframe, a delta against it, a delta predicted from both.
  protocol::Frame snapshots{63};
  for (const char* name : {"snapshot", "delta_snapshot", "predicted_snapshot"})
    for (const auto& [n, f] : frames)
      if (n == name) snapshots.insert(snapshots.end(), f.begin(), f.end());

  const std::string dir = argv[1];
  for (const auto& [name, frame] : frames) {
    std::ofstream out(dir + "/" + name, std::ios::binary);
    const char chunk_byte = 63;  // the largest chunk: whole frames at once
    out.write(&chunk_byte, 1);
    out.write(reinterpret_cast<const char*>(frame.data()), static_cast<std::streamsize>(frame.size()));
  }
  std::ofstream(dir + "/conversation", std::ios::binary)
      .write(reinterpret_cast<const char*>(conversation.data()), static_cast<std::streamsize>(conversation.size()));
  std::ofstream(dir + "/keyframe_then_delta", std::ios::binary)
      .write(reinterpret_cast<const char*>(snapshots.data()), static_cast<std::streamsize>(snapshots.size()));
  return 0;
}
