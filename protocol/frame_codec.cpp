#include "protocol/frame_codec.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace fishtank::protocol {

namespace {

// Message -> payload table -> vector is three levels and two tables; a little
// room above that, and nothing like the defaults (64 levels, a million tables).
constexpr flatbuffers::uoffset_t kMaxDepth = 8;
constexpr flatbuffers::uoffset_t kMaxTables = 8;
// The smallest FlatBuffers buffer: root offset and file identifier.
constexpr std::uint32_t kMinBodyBytes = 8;

wire::Vec3f to_wire(Vec3 v) { return {v.x, v.y, v.z}; }

template <typename T>
Frame finish(flatbuffers::FlatBufferBuilder& b, flatbuffers::Offset<T> payload) {
  const auto message = wire::CreateMessage(b, wire::PayloadTraits<T>::enum_value, payload.Union());
  b.FinishSizePrefixed(message, kFileIdentifier);
  return Frame(b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize());
}

bool finite(const wire::Vec3f* v) {
  return v && std::isfinite(v->x()) && std::isfinite(v->y()) && std::isfinite(v->z());
}

// Finite corners with lo below hi on every axis.
bool ordered_box(const wire::Vec3f* lo, const wire::Vec3f* hi) {
  return finite(lo) && finite(hi) && lo->x() < hi->x() && lo->y() < hi->y() && lo->z() < hi->z();
}

DecodeResult failure(DecodeStatus status, std::string why) { return {status, nullptr, std::move(why)}; }

bool accepted_by(wire::Payload type, Direction to) {
  switch (type) {
    case wire::Payload::Hello:
    case wire::Payload::PlayerInput:
    case wire::Payload::AddBalls:
    case wire::Payload::Ping:
    case wire::Payload::Pause:
    case wire::Payload::Step:
    case wire::Payload::Reset:
    case wire::Payload::SetTimeScale:
    case wire::Payload::Ack:
    case wire::Payload::Watching:
      return to == Direction::to_server;
    case wire::Payload::Welcome:
    case wire::Payload::BallKinds:
    case wire::Payload::Snapshot:
    case wire::Payload::Error:
    case wire::Payload::Pong:
    case wire::Payload::PlayerGranted:
    case wire::Payload::InLine:
      return to == Direction::to_client;
    default:
      return false;
  }
}

// A full snapshot has 3 positions per ball; a delta has no positions, and an
// unchanged mask of one bit per ball it shares with its base.
std::string check_positions(const wire::Snapshot& s) {
  if (s.unchanged()) {
    if (s.positions() || !s.changes()) return "delta Snapshot has positions, or lacks its changes";
    const std::size_t expected = unchanged_mask_bytes(s.base_ball_count(), s.ball_count());
    if (s.unchanged()->size() != expected)
      return "delta Snapshot has an unchanged mask of " + std::to_string(s.unchanged()->size()) + " bytes for " +
             std::to_string(expected) + " bytes of balls (truncated or overlong)";
    // Checked here, before a reader allocates ball_count positions (found by fuzzing).
    const std::uint64_t new_balls = s.ball_count() - std::min(s.base_ball_count(), s.ball_count());
    if (new_balls * 6 > s.changes()->size())
      return "delta Snapshot has " + std::to_string(new_balls) + " new balls but only " +
             std::to_string(s.changes()->size()) + " bytes of changes (6 per new ball at least)";
    return {};
  }
  if (!s.positions()) return "Snapshot lacks its positions vector";
  const std::uint64_t values = s.positions()->size();
  if (values != 3 * std::uint64_t{s.ball_count()})
    return "Snapshot has " + std::to_string(values) + " position values for " + std::to_string(s.ball_count()) +
           " balls (3 per ball expected)";
  return {};
}

// Values the Verifier cannot judge. Empty when the message is usable.
std::string check_values(const wire::Message& m) {
  switch (m.payload_type()) {
    case wire::Payload::Hello: {
      const auto* name = m.payload_as_Hello()->client_name();
      if (name && name->size() > kMaxClientNameBytes)
        return "client_name is " + std::to_string(name->size()) + " bytes; at most " +
               std::to_string(kMaxClientNameBytes) + " are allowed";
      return {};
    }
    case wire::Payload::PlayerInput:
      if (!finite(m.payload_as_PlayerInput()->velocity())) return "PlayerInput.velocity is missing or not finite";
      return {};
    case wire::Payload::AddBalls: {
      const std::uint32_t count = m.payload_as_AddBalls()->count();
      if (count < 1 || count > kMaxAddBallsPerRequest)
        return "AddBalls.count must be between 1 and " + std::to_string(kMaxAddBallsPerRequest) + ", got " +
               std::to_string(count);
      return {};
    }
    case wire::Payload::Ping:
    case wire::Payload::Pong:
    case wire::Payload::PlayerGranted:
    case wire::Payload::InLine:
    case wire::Payload::Pause:
    case wire::Payload::Watching:
    case wire::Payload::Ack:  // any tick: only the session knows which it sent
      return {};
    case wire::Payload::Step: {
      const std::uint32_t count = m.payload_as_Step()->count();
      if (count < 1 || count > kMaxStepsPerRequest)
        return "Step.count must be between 1 and " + std::to_string(kMaxStepsPerRequest) + ", got " +
               std::to_string(count);
      return {};
    }
    case wire::Payload::Reset: {
      const auto* scene = m.payload_as_Reset()->scene();
      if (scene && scene->size() > kMaxSceneNameBytes)
        return "Reset.scene is " + std::to_string(scene->size()) + " bytes; scene names are at most " +
               std::to_string(kMaxSceneNameBytes);
      return {};
    }
    case wire::Payload::SetTimeScale: {
      const float scale = m.payload_as_SetTimeScale()->scale();
      // Written so that NaN fails too.
      if (scale >= kMinTimeScale && scale <= kMaxTimeScale) return {};
      char why[96];
      std::snprintf(why, sizeof why, "SetTimeScale.scale must be between %g and %g, got %g", kMinTimeScale,
                    kMaxTimeScale, scale);
      return why;
    }
    case wire::Payload::Welcome: {
      const wire::Welcome& w = *m.payload_as_Welcome();
      if (!w.server_variant() || !w.simd_level()) return "Welcome lacks server_variant or simd_level";
      if (!finite(w.tank_min()) || !finite(w.tank_max())) return "Welcome tank bounds are missing or not finite";
      if (!ordered_box(w.tank_min(), w.tank_max())) return "Welcome tank_min is not below tank_max on every axis";
      if (!std::isfinite(w.dt()) || w.dt() <= 0.0f) return "Welcome.dt is not a positive number";
      if (!w.ball_kinds() || w.ball_kinds()->size() == 0 || w.ball_kinds()->size() > 256)
        return "Welcome.ball_kinds must list 1 to 256 kinds";
      for (const wire::BallKindInfo* k : *w.ball_kinds())
        if (!std::isfinite(k->diameter()) || k->diameter() <= 0.0f || !std::isfinite(k->mass()) || k->mass() <= 0.0f)
          return "Welcome.ball_kinds has a non-positive or non-finite diameter or mass";
      return {};
    }
    case wire::Payload::BallKinds: {
      const wire::BallKinds& k = *m.payload_as_BallKinds();
      if (!k.kinds()) return "BallKinds.kinds is missing";
      if (std::uint64_t{k.first_new_ball()} + k.kinds()->size() > UINT32_MAX) return "BallKinds ball ids overflow";
      return {};
    }
    case wire::Payload::Snapshot: {
      const wire::Snapshot& s = *m.payload_as_Snapshot();
      if (!s.player_ids() || !s.player_positions()) return "Snapshot lacks its player_ids or player_positions vector";
      if (std::string why = check_positions(s); !why.empty()) return why;
      if (s.player_ids()->size() != s.player_positions()->size())
        return "Snapshot player_ids and player_positions differ in length";
      for (const wire::Vec3f* p : *s.player_positions())
        if (!finite(p)) return "Snapshot has a non-finite player position";
      if (!std::isfinite(s.sim_time()) || !std::isfinite(s.steps_per_s()) || !std::isfinite(s.load()) ||
          !std::isfinite(s.time_scale()) || !std::isfinite(s.time_scale_set()) ||
          !std::isfinite(s.kinetic_energy_per_ball()) || !std::isfinite(s.max_overlap()))
        return "Snapshot has a non-finite time, rate, load, time scale, energy or overlap";
      if (!s.tank_min() != !s.tank_max()) return "Snapshot has one tank corner without the other";
      if (s.tank_min() && !ordered_box(s.tank_min(), s.tank_max()))
        return "Snapshot tank bounds are not finite, or tank_min is not below tank_max on every axis";
      return {};
    }
    case wire::Payload::Error:
      if (!m.payload_as_Error()->message()) return "Error.message is missing";
      return {};
    default:
      return "unknown payload type";
  }
}

}  // namespace

Frame encode_hello(std::string_view client_name, bool wants_player, bool acknowledges, std::uint32_t version) {
  flatbuffers::FlatBufferBuilder b(128);
  const auto name = b.CreateString(client_name.data(), client_name.size());
  return finish(b, wire::CreateHello(b, version, name, wants_player, acknowledges));
}

Frame encode_player_input(std::uint32_t sequence, Vec3 velocity) {
  flatbuffers::FlatBufferBuilder b(64);
  const wire::Vec3f v = to_wire(velocity);
  return finish(b, wire::CreatePlayerInput(b, sequence, &v));
}

Frame encode_add_balls(std::uint32_t count) {
  flatbuffers::FlatBufferBuilder b(64);
  return finish(b, wire::CreateAddBalls(b, count));
}

Frame encode_ping(std::uint32_t client_time_us) {
  flatbuffers::FlatBufferBuilder b(64);
  return finish(b, wire::CreatePing(b, client_time_us));
}

Frame encode_pause(bool paused) {
  flatbuffers::FlatBufferBuilder b(64);
  return finish(b, wire::CreatePause(b, paused));
}

Frame encode_step(std::uint32_t count) {
  flatbuffers::FlatBufferBuilder b(64);
  return finish(b, wire::CreateStep(b, count));
}

Frame encode_reset(std::string_view scene, std::optional<std::uint64_t> seed) {
  flatbuffers::FlatBufferBuilder b(128);
  flatbuffers::Offset<flatbuffers::String> name;
  if (!scene.empty()) name = b.CreateString(scene.data(), scene.size());
  wire::ResetBuilder reset(b);
  if (!scene.empty()) reset.add_scene(name);
  if (seed) reset.add_seed(*seed);
  return finish(b, reset.Finish());
}

Frame encode_set_time_scale(float scale) {
  flatbuffers::FlatBufferBuilder b(64);
  return finish(b, wire::CreateSetTimeScale(b, scale));
}

Frame encode_ack(std::uint32_t tick, bool want_keyframe) {
  flatbuffers::FlatBufferBuilder b(64);
  return finish(b, wire::CreateAck(b, tick, want_keyframe));
}

Frame encode_watching(bool on) {
  flatbuffers::FlatBufferBuilder b(64);
  return finish(b, wire::CreateWatching(b, on));
}

Frame encode_welcome(const WelcomeInfo& info) {
  flatbuffers::FlatBufferBuilder b(512);
  const auto variant = b.CreateString(info.server_variant);
  const auto simd = b.CreateString(info.simd_level);
  std::vector<wire::BallKindInfo> kinds;
  for (const BallKind& k : kBallKinds) kinds.emplace_back(k.diameter, k.mass, k.rgb[0], k.rgb[1], k.rgb[2]);
  const auto kinds_offset = b.CreateVectorOfStructs(kinds);
  const auto policy = b.CreateString(info.control_policy);
  const wire::Vec3f tank_min = to_wire(info.tank.min), tank_max = to_wire(info.tank.max);
  return finish(b, wire::CreateWelcome(b, kProtocolVersion, info.client_id, variant, simd, info.worker_threads,
                                       &tank_min, &tank_max, info.dt, kinds_offset, info.player_id.has_value(),
                                       info.player_id.value_or(0), info.snapshot_rate_hz, policy, info.may_control,
                                       info.steps_per_contact, info.tolerance, info.observers_may_control));
}

Frame encode_ball_kinds(std::uint32_t first_new_ball, const std::uint8_t* kinds, std::size_t count) {
  flatbuffers::FlatBufferBuilder b(64 + count);
  const auto kinds_offset = b.CreateVector(kinds, count);
  return finish(b, wire::CreateBallKinds(b, first_new_ball, kinds_offset));
}

namespace {

// Positions are added by the caller: the full vector, or a delta's fields.
template <class AddPositions>
Frame encode_snapshot_with(const SnapshotHeader& header, std::uint32_t ball_count, const std::uint32_t* player_ids,
                           const Vec3* player_positions, std::size_t players, std::size_t position_bytes,
                           AddPositions add_positions) {
  flatbuffers::FlatBufferBuilder b(256 + position_bytes + 16 * players);
  const auto positions = add_positions(b);
  const auto ids = b.CreateVector(player_ids, players);
  // Not CreateUninitializedVectorOfStructs: in FlatBuffers 2.0.8 it aligns a
  // 12-byte struct to 12 bytes, which corrupts the buffer.
  std::vector<wire::Vec3f> player_wire(players);
  for (std::size_t i = 0; i < players; ++i) player_wire[i] = to_wire(player_positions[i]);
  const auto player_offset = b.CreateVectorOfStructs(player_wire);
  const auto scene = b.CreateString(header.scene);
  const wire::Vec3f tank_min = to_wire(header.tank.min), tank_max = to_wire(header.tank.max);
  wire::SnapshotBuilder s(b);
  s.add_tick(header.tick);
  s.add_sim_time(header.sim_time);
  s.add_physics_steps(header.physics_steps);
  s.add_steps_per_s(header.steps_per_s);
  s.add_load(header.load);
  s.add_ball_count(ball_count);
  s.add_player_ids(ids);
  s.add_player_positions(player_offset);
  s.add_threads_stepping(header.threads_stepping);
  s.add_time_scale(header.time_scale);
  s.add_paused(header.paused);
  s.add_time_scale_set(header.time_scale_set);
  s.add_scene(scene);
  s.add_scene_start(header.scene_start);
  s.add_tank_min(&tank_min);
  s.add_tank_max(&tank_max);
  s.add_kinetic_energy_per_ball(header.kinetic_energy_per_ball);
  s.add_contacts(header.contacts);
  s.add_max_overlap(header.max_overlap);
  positions.add_to(s);
  return finish(b, s.Finish());
}

}  // namespace

Frame encode_snapshot(const SnapshotHeader& header, const std::uint16_t* quantised, std::uint32_t ball_count,
                      const std::uint32_t* player_ids, const Vec3* player_positions, std::size_t players) {
  struct Full {
    flatbuffers::Offset<flatbuffers::Vector<std::uint16_t>> positions;
    void add_to(wire::SnapshotBuilder& s) const { s.add_positions(positions); }
  };
  const std::size_t values = 3 * std::size_t{ball_count};
  return encode_snapshot_with(
      header, ball_count, player_ids, player_positions, players, 2 * values,
      [&](flatbuffers::FlatBufferBuilder& b) { return Full{b.CreateVector(quantised, values)}; });
}

Frame encode_delta_snapshot(const SnapshotHeader& header, const DeltaReference& ref, const PositionsDelta& delta,
                            std::uint32_t ball_count, const std::uint32_t* player_ids, const Vec3* player_positions,
                            std::size_t players) {
  struct Delta {
    const DeltaReference& ref;
    flatbuffers::Offset<flatbuffers::Vector<std::uint8_t>> unchanged, changes;
    void add_to(wire::SnapshotBuilder& s) const {
      s.add_base_tick(ref.base_tick);
      s.add_base_ball_count(ref.base_count);
      s.add_unchanged(unchanged);
      s.add_changes(changes);
      s.add_prior_tick(ref.prior_tick);
      s.add_predicted(ref.prior != nullptr);
    }
  };
  return encode_snapshot_with(header, ball_count, player_ids, player_positions, players,
                              delta.unchanged.size() + delta.changes.size(), [&](flatbuffers::FlatBufferBuilder& b) {
                                return Delta{ref, b.CreateVector(delta.unchanged), b.CreateVector(delta.changes)};
                              });
}

Frame encode_error(wire::ErrorCode code, std::string_view message) {
  flatbuffers::FlatBufferBuilder b(128 + message.size());
  const auto text = b.CreateString(message.data(), message.size());
  return finish(b, wire::CreateError(b, code, text));
}

Frame encode_player_granted(std::uint32_t player_id, bool may_control) {
  flatbuffers::FlatBufferBuilder b(64);
  return finish(b, wire::CreatePlayerGranted(b, player_id, may_control));
}

Frame encode_in_line(std::uint32_t ahead) {
  flatbuffers::FlatBufferBuilder b(64);
  return finish(b, wire::CreateInLine(b, ahead));
}

Frame encode_pong(std::uint32_t client_time_us) {
  flatbuffers::FlatBufferBuilder b(64);
  return finish(b, wire::CreatePong(b, client_time_us));
}

std::uint32_t max_frame_bytes(Direction to) {
  return to == Direction::to_server ? kMaxClientFrameBytes : kMaxServerFrameBytes;
}

std::string error_code_name(wire::ErrorCode code) {
  const char* name = wire::EnumNameErrorCode(code);
  return *name ? name : std::to_string(static_cast<int>(code));
}

bool ends_connection(wire::ErrorCode code) {
  using C = wire::ErrorCode;
  switch (code) {
    case C::malformed_frame:
    case C::version_mismatch:
    case C::expected_hello:
    case C::too_slow:
    case C::server_full:
    case C::hello_timeout:
    case C::idle_timeout:
    case C::command_flood:
    case C::wrong_port:
    case C::server_stopping:
      return true;
    default:
      return false;
  }
}

DecodeResult check_length_prefix(const std::uint8_t prefix[kLengthPrefixBytes], Direction to,
                                 std::uint32_t* body_bytes) {
  const std::uint32_t length = std::uint32_t{prefix[0]} | std::uint32_t{prefix[1]} << 8 |
                               std::uint32_t{prefix[2]} << 16 | std::uint32_t{prefix[3]} << 24;
  if (length < kMinBodyBytes || length > max_frame_bytes(to))
    return failure(DecodeStatus::bad_length, "frame length " + std::to_string(length) + " is outside " +
                                                 std::to_string(kMinBodyBytes) + " .. " +
                                                 std::to_string(max_frame_bytes(to)) + " bytes");
  *body_bytes = length;
  return {};
}

DecodeResult decode_frame(const std::uint8_t* frame, std::size_t size, Direction to) {
  std::uint32_t body_bytes = 0;
  if (size < kLengthPrefixBytes) return failure(DecodeStatus::bad_length, "frame shorter than its length prefix");
  if (DecodeResult r = check_length_prefix(frame, to, &body_bytes); !r.ok()) return r;
  if (size != kLengthPrefixBytes + body_bytes)
    return failure(DecodeStatus::bad_length, "length prefix does not match the frame size");
  if (!flatbuffers::BufferHasIdentifier(frame, kFileIdentifier, /*size_prefixed=*/true))
    return failure(DecodeStatus::malformed, "not a Fishtank frame (file identifier is not FTNK)");
  flatbuffers::Verifier verifier(frame, size, kMaxDepth, kMaxTables);
  if (!wire::VerifySizePrefixedMessageBuffer(verifier))
    return failure(DecodeStatus::malformed, "frame failed FlatBuffers verification");
  const wire::Message* message = wire::GetSizePrefixedMessage(frame);
  if (message->payload_type() == wire::Payload::NONE) return failure(DecodeStatus::invalid_value, "empty message");
  // The Verifier accepts a union type without its table (found by the fuzzer):
  // every payload_as_*() would then return null.
  if (!message->payload()) return failure(DecodeStatus::invalid_value, "message has a type but no body");
  if (!accepted_by(message->payload_type(), to))
    return failure(DecodeStatus::wrong_direction,
                   std::string("message type ") +
                       (message->payload_type() <= wire::Payload::MAX ? wire::EnumNamePayload(message->payload_type())
                                                                      : "unknown") +
                       (to == Direction::to_server ? " is not accepted by the server" : " is not sent by servers"));
  if (std::string why = check_values(*message); !why.empty()) return failure(DecodeStatus::invalid_value, why);
  return {DecodeStatus::ok, message, {}};
}

void FrameReader::append(const std::uint8_t* data, std::size_t size) {
  if (!broken_) pending_.insert(pending_.end(), data, data + size);
}

std::optional<DecodeResult> FrameReader::next() {
  if (broken_) return broken_;
  if (pending_.size() < kLengthPrefixBytes) return std::nullopt;
  std::uint32_t body_bytes = 0;
  if (DecodeResult r = check_length_prefix(pending_.data(), to_, &body_bytes); !r.ok()) {
    pending_.clear();
    frame_.clear();
    broken_ = r;
    return broken_;
  }
  const std::size_t frame_bytes = kLengthPrefixBytes + body_bytes;
  if (pending_.size() < frame_bytes) return std::nullopt;
  frame_.assign(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(frame_bytes));
  pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(frame_bytes));
  DecodeResult r = decode_frame(frame_.data(), frame_.size(), to_);
  if (r.stream_broken()) {
    pending_.clear();
    broken_ = r;
  }
  return r;
}

}  // namespace fishtank::protocol
