#pragma once
// Frames on the wire, for every side (server, viewer, fishtank-client).
//
//   frame = [length: uint32 little-endian][FlatBuffers buffer of `length` bytes,
//            root Message, file identifier "FTNK"]           (protocol/fishtank.fbs)
//
// Encoding: one encode_* function per message, each returning a complete frame.
// Decoding is done in this order, so nothing untrusted is allocated or read first:
//   1. check_length_prefix: the length must be 8 .. the direction's cap
//      (kMaxClientFrameBytes for client -> server, kMaxServerFrameBytes the other way),
//      checked before the body is allocated;
//   2. decode_frame: FlatBuffers Verifier (tight max_depth / max_tables), then the
//      values: finite floats, counts in range, vector lengths that agree, and a
//      payload type that the receiving side accepts.
// When decoding is ok, the payload table and every field a reader needs are
// present (the Verifier alone allows them to be absent): Hello.client_name may
// be null; a Snapshot has either positions or (a delta) unchanged and changes;
// everything else in fishtank.fbs may be dereferenced.
// A bad length or a failed verification breaks the stream (stream_broken()): the
// reader cannot tell where the next frame starts, so it should disconnect.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "common/tank.h"
#include "common/vec3.h"
#include "protocol/fishtank_generated.h"
#include "protocol/snapshot_delta.h"

namespace fishtank::protocol {

inline constexpr std::uint32_t kProtocolVersion = 1;
inline constexpr char kFileIdentifier[] = "FTNK";
inline constexpr std::size_t kLengthPrefixBytes = 4;
// Client frames are small commands: 1 MiB is far more than any needs.
inline constexpr std::uint32_t kMaxClientFrameBytes = 1u << 20;
// Server frames carry 6 bytes per ball: 64 MiB holds a snapshot of ~11 M balls,
// more than the server's own --max-balls limit of 10 M.
inline constexpr std::uint32_t kMaxServerFrameBytes = 64u << 20;
inline constexpr std::uint32_t kMaxAddBallsPerRequest = 100'000;
inline constexpr std::size_t kMaxClientNameBytes = 64;
inline constexpr std::uint32_t kMaxStepsPerRequest = 100'000;
// The slowest and fastest clock people may ask for (SetTimeScale).
inline constexpr float kMinTimeScale = 0.1f;
inline constexpr float kMaxTimeScale = 1.0f;
inline constexpr std::size_t kMaxSceneNameBytes = 32;

using Frame = std::vector<std::uint8_t>;  // one complete frame, length prefix included
using SharedFrame = std::shared_ptr<const Frame>;

enum class Direction { to_server, to_client };

// ---- encoding: client -> server ----
Frame encode_hello(std::string_view client_name, bool wants_player, bool acknowledges,
                   std::uint32_t version = kProtocolVersion);
Frame encode_player_input(std::uint32_t sequence, Vec3 velocity);
Frame encode_add_balls(std::uint32_t count);
Frame encode_ping(std::uint32_t client_time_us);
Frame encode_pause(bool paused);
Frame encode_step(std::uint32_t count);
// An empty scene restarts the scene running; no seed keeps the scene's last seed.
Frame encode_reset(std::string_view scene, std::optional<std::uint64_t> seed);
Frame encode_set_time_scale(float scale);
Frame encode_ack(std::uint32_t tick, bool want_keyframe = false);
// Off: no Snapshots for this client until on again (a page in a hidden tab).
Frame encode_watching(bool on);

// ---- encoding: server -> client ----
struct WelcomeInfo {
  std::uint32_t client_id = 0;
  std::string server_variant;  // the kernel set: "scalar", "sse" or "avx2"
  std::string simd_level;
  std::uint32_t worker_threads = 1;
  TankBounds tank;
  float dt = 0.0f;
  std::optional<std::uint32_t> player_id;  // empty: the client observes
  float snapshot_rate_hz = 0.0f;
  std::string control_policy;          // who may pause, step, reset and set the time scale, in words
  bool may_control = false;            // whether this client may
  float steps_per_contact = 0.0f;      // contact duration of the lightest pair / dt
  float tolerance = 0.0f;              // the per-collision error dt was chosen for; 0: dt given
  bool observers_may_control = false;  // whether a client without a player sphere may
};
Frame encode_welcome(const WelcomeInfo& info);

// kinds[i] is the kind of ball first_new_ball + i.
Frame encode_ball_kinds(std::uint32_t first_new_ball, const std::uint8_t* kinds, std::size_t count);

struct SnapshotHeader {
  std::uint32_t tick = 0;
  double sim_time = 0.0;
  std::uint32_t physics_steps = 0;
  float steps_per_s = 0.0f;
  float load = 0.0f;
  std::uint32_t threads_stepping = 0;  // 0: not reported
  float time_scale = 0.0f;             // simulated seconds per wall second; 0: not reported
  bool paused = false;
  float time_scale_set = 0.0f;  // asked for (SetTimeScale); 0: not reported
  std::string scene;
  std::uint32_t scene_start = 0;
  TankBounds tank;  // the running scene's: the quantisation bounds
  float kinetic_energy_per_ball = 0.0f;
  std::uint32_t contacts = 0;
  float max_overlap = 0.0f;  // fraction of the smaller radius
};
// quantised holds 3 * ball_count values (protocol/quantize.h), in ball-id order;
// player_ids and player_positions hold `players` entries each.
Frame encode_snapshot(const SnapshotHeader& header, const std::uint16_t* quantised, std::uint32_t ball_count,
                      const std::uint32_t* player_ids, const Vec3* player_positions, std::size_t players);
// The same snapshot with its positions coded against `ref` (protocol/snapshot_delta.h).
Frame encode_delta_snapshot(const SnapshotHeader& header, const DeltaReference& ref, const PositionsDelta& delta,
                            std::uint32_t ball_count, const std::uint32_t* player_ids, const Vec3* player_positions,
                            std::size_t players);

Frame encode_error(wire::ErrorCode code, std::string_view message);
// An Error's code as clients print it: its name, or its number where it is newer than this build.
std::string error_code_name(wire::ErrorCode code);
// Whether an Error of this code is the server's last word on the connection (a disconnect follows).
bool ends_connection(wire::ErrorCode code);
Frame encode_pong(std::uint32_t client_time_us);
// A sphere freed by another client, for this one that waited in line (may_control: under the policy, now).
Frame encode_player_granted(std::uint32_t player_id, bool may_control);
// This client's place in line for a sphere: `ahead` clients before it.
Frame encode_in_line(std::uint32_t ahead);

// ---- decoding ----
enum class DecodeStatus {
  ok,
  bad_length,      // length prefix out of range: the stream cannot be trusted
  malformed,       // wrong identifier or failed verification: the stream cannot be trusted
  invalid_value,   // well-formed, but a value is unusable (NaN, inf, count out of range, missing field)
  wrong_direction  // well-formed, but not a message the receiving side accepts (or an unknown type)
};

struct DecodeResult {
  DecodeStatus status = DecodeStatus::ok;
  // Non-null only when ok; points into the frame, so it is valid as long as the frame is.
  const wire::Message* message = nullptr;
  std::string why;  // empty when ok; otherwise one sentence for logs and Error messages

  bool ok() const { return status == DecodeStatus::ok; }
  bool stream_broken() const { return status == DecodeStatus::bad_length || status == DecodeStatus::malformed; }
};

std::uint32_t max_frame_bytes(Direction to);

// Reads the 4-byte prefix; on success *body_bytes is the length that follows it.
DecodeResult check_length_prefix(const std::uint8_t prefix[kLengthPrefixBytes], Direction to,
                                 std::uint32_t* body_bytes);

// Checks one complete frame (prefix included) sent in direction `to`. The frame
// should start at an 8-byte-aligned address (a std::vector's data() is).
DecodeResult decode_frame(const std::uint8_t* frame, std::size_t size, Direction to);

// Splits a byte stream into decoded frames, for readers that receive arbitrary
// chunks (fishtank-client, the fuzzer). It buffers at most one frame plus the
// last chunk appended.
class FrameReader {
 public:
  explicit FrameReader(Direction to) : to_(to) {}

  void append(const std::uint8_t* data, std::size_t size);
  // The next complete frame, decoded, or nothing while more bytes are needed.
  // The result's message points into frame() and stays valid until the next call.
  // After a stream_broken() result, the reader returns that result forever.
  std::optional<DecodeResult> next();
  // The frame of the last result; empty after a bad length prefix (no frame was cut).
  const Frame& frame() const { return frame_; }

 private:
  Direction to_;
  std::vector<std::uint8_t> pending_;  // bytes received and not yet returned as a frame
  Frame frame_;                        // the frame last returned, copied out so it is aligned
  std::optional<DecodeResult> broken_;
};

}  // namespace fishtank::protocol
