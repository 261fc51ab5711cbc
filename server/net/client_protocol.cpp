#include "server/net/client_protocol.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "common/printable_text.h"
#include "common/scene_names.h"

namespace fishtank::net {

namespace {
// "5 s", "0.5 s": a limit as the flag gave it.
std::string seconds_text(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%g s", s);
  return text;
}
}  // namespace

ClientProtocol::ClientProtocol(std::uint32_t client_id, const ServerInfo& info)
    : client_id_(client_id),
      info_(info),
      commands_(info.limits.max_commands_per_s, info.limits.max_commands_per_s),
      ack_budget_(2.0 * info.snapshot_rate_hz, 2.0 * info.snapshot_rate_hz),
      balls_(info.limits.add_balls_per_minute / 60.0, info.limits.add_balls_per_minute) {}

Outcome ClientProtocol::refuse(wire::ErrorCode code, const std::string& why, bool disconnect) {
  Outcome out;
  out.replies.push_back(protocol::encode_error(code, why));
  out.disconnect = disconnect;
  out.log = std::string(wire::EnumNameErrorCode(code)) + ": " + why + (disconnect ? " (disconnecting)" : "");
  return out;
}

Outcome ClientProtocol::on_broken_stream(const protocol::DecodeResult& refused) {
  return refuse(wire::ErrorCode::malformed_frame, refused.why, /*disconnect=*/true);
}

protocol::DecodeResult ClientProtocol::check_length_prefix(const std::uint8_t* prefix,
                                                           std::uint32_t* body_bytes) const {
  protocol::DecodeResult r = protocol::check_length_prefix(prefix, protocol::Direction::to_server, body_bytes);
  if (r.ok() && !hello_received() && *body_bytes > kMaxFirstFrameBytes)
    return {protocol::DecodeStatus::bad_length, nullptr,
            "the first frame announces " + std::to_string(*body_bytes) + " bytes; a Hello is at most " +
                std::to_string(kMaxFirstFrameBytes)};
  return r;
}

std::uint32_t ClientProtocol::max_body_bytes() const {
  return hello_received() ? protocol::kMaxClientFrameBytes : kMaxFirstFrameBytes;
}

Outcome ClientProtocol::on_unprefixed_frame(const std::uint8_t* body, std::size_t size, Clock::time_point now) {
  if (size > max_body_bytes())
    return on_broken_stream({protocol::DecodeStatus::bad_length, nullptr,
                             "a message of " + std::to_string(size) + " bytes; at most " +
                                 std::to_string(max_body_bytes()) + " are accepted" +
                                 (hello_received() ? "" : " before Hello")});
  const auto length = static_cast<std::uint32_t>(size);
  unprefixed_.resize(protocol::kLengthPrefixBytes + size);
  for (std::size_t i = 0; i < protocol::kLengthPrefixBytes; ++i)
    unprefixed_[i] = static_cast<std::uint8_t>(length >> (8 * i));
  if (size > 0) std::memcpy(unprefixed_.data() + protocol::kLengthPrefixBytes, body, size);
  Outcome out = on_frame(unprefixed_.data(), unprefixed_.size(), now);
  // A large message's buffer is not kept for the small ones that follow.
  if (unprefixed_.capacity() > 16 * 1024) protocol::Frame().swap(unprefixed_);
  return out;
}

Outcome ClientProtocol::on_frame(const std::uint8_t* frame, std::size_t size, Clock::time_point now) {
  const protocol::DecodeResult decoded = protocol::decode_frame(frame, size, protocol::Direction::to_server);
  if (decoded.stream_broken()) return on_broken_stream(decoded);
  // Acks answer snapshots, so their allowance follows the snapshot rate, not --max-commands.
  const bool ack = decoded.ok() && decoded.message->payload_type() == wire::Payload::Ack;
  if (hello_received() && !(ack ? ack_budget_ : commands_).take(1.0, now))
    return refuse(wire::ErrorCode::command_flood,
                  ack ? "more than " + std::to_string(std::lround(2.0 * info_.snapshot_rate_hz)) +
                            " acknowledgements a second (twice the snapshot rate)"
                      : "more than " + std::to_string(std::lround(info_.limits.max_commands_per_s)) +
                            " messages a second (--max-commands)",
                  /*disconnect=*/true);
  if (state_ == State::awaiting_hello) {
    if (!decoded.ok() || decoded.message->payload_type() != wire::Payload::Hello)
      return refuse(
          wire::ErrorCode::expected_hello,
          "the first message must be a valid Hello" + (decoded.ok() ? std::string() : " (" + decoded.why + ")"),
          /*disconnect=*/true);
    return on_hello(*decoded.message->payload_as_Hello());
  }
  if (decoded.status == protocol::DecodeStatus::invalid_value)
    return refuse(wire::ErrorCode::invalid_value, decoded.why + "; message ignored", /*disconnect=*/false);
  if (decoded.status == protocol::DecodeStatus::wrong_direction)
    return refuse(wire::ErrorCode::unexpected_message, decoded.why, /*disconnect=*/false);
  return on_message(*decoded.message, now);
}

Outcome ClientProtocol::on_hello(const wire::Hello& hello) {
  if (hello.client_name()) name_ = printable_text(hello.client_name()->str(), kMaxNameBytes);
  if (hello.protocol_version() != protocol::kProtocolVersion)
    return refuse(wire::ErrorCode::version_mismatch,
                  "this server speaks protocol version " + std::to_string(protocol::kProtocolVersion) +
                      ", the client speaks version " + std::to_string(hello.protocol_version()) +
                      "; use a client and server from the same release",
                  /*disconnect=*/true);
  state_ = State::joining;
  if (hello.acknowledges()) acks_.expect_acks();
  Outcome out;
  out.command = Command{client_id_, JoinCommand{hello.wants_player()}};
  out.log = "hello from '" + name_ + "'" + (hello.wants_player() ? ", wants a player sphere" : ", observing");
  return out;
}

Outcome ClientProtocol::on_message(const wire::Message& message, Clock::time_point now) {
  Outcome out;
  switch (message.payload_type()) {
    case wire::Payload::Hello:
      return refuse(wire::ErrorCode::unexpected_message, "Hello was already received; message ignored", false);
    case wire::Payload::PlayerInput: {
      const wire::Vec3f& v = *message.payload_as_PlayerInput()->velocity();
      if (v.x() != 0.0f || v.y() != 0.0f || v.z() != 0.0f) last_used_ = now;
      out.command = Command{client_id_, SetVelocityCommand{{v.x(), v.y(), v.z()}}};
      return out;
    }
    case wire::Payload::AddBalls:
      last_used_ = now;  // a script that pours, pauses and steps is there, though its sphere stands still
      return on_add_balls(message.payload_as_AddBalls()->count(), now);
    case wire::Payload::Ping:
      out.replies.push_back(protocol::encode_pong(message.payload_as_Ping()->client_time_us()));
      return out;
    case wire::Payload::Pause:
    case wire::Payload::Step:
    case wire::Payload::Reset:
    case wire::Payload::SetTimeScale:
      last_used_ = now;
      return on_control(message);
    case wire::Payload::Watching:
      watching_ = message.payload_as_Watching()->on();
      if (!watching_) acks_.forget_unanswered();
      return out;
    case wire::Payload::Ack: {
      const wire::Ack& ack = *message.payload_as_Ack();
      if (std::string why = acks_.acknowledged(ack.tick(), ack.want_keyframe(), now); !why.empty())
        return refuse(wire::ErrorCode::invalid_value, why, /*disconnect=*/false);
      return out;
    }
    default:  // decode_frame accepts nothing else in this direction
      return refuse(wire::ErrorCode::unexpected_message, "message type not accepted by the server", false);
  }
}

Outcome ClientProtocol::on_control(const wire::Message& message) {
  if (!may_control(info_.control, has_player_))
    return refuse(wire::ErrorCode::not_permitted,
                  std::string(wire::EnumNamePayload(message.payload_type())) + " refused: " + describe(info_.control),
                  /*disconnect=*/false);
  Outcome out;
  switch (message.payload_type()) {
    case wire::Payload::Pause:
      out.command = Command{client_id_, PauseCommand{message.payload_as_Pause()->paused()}};
      break;
    case wire::Payload::Step:
      out.command = Command{client_id_, StepCommand{message.payload_as_Step()->count()}};
      break;
    case wire::Payload::Reset: {
      const wire::Reset& r = *message.payload_as_Reset();
      ResetCommand reset;
      if (r.scene()) {
        reset.scene = r.scene()->str();
        if (!is_scene_name(*reset.scene))
          return refuse(wire::ErrorCode::invalid_value,
                        "unknown scene '" + printable_text(*reset.scene, kMaxNameBytes) + "'; the scenes are " +
                            scene_names_text(),
                        /*disconnect=*/false);
      }
      if (r.seed()) reset.seed = *r.seed();
      out.command = Command{client_id_, std::move(reset)};
      break;
    }
    default:  // SetTimeScale: decode_frame checked its range
      out.command = Command{client_id_, TimeScaleCommand{message.payload_as_SetTimeScale()->scale()}};
      break;
  }
  return out;
}

Outcome ClientProtocol::on_add_balls(std::uint32_t count, Clock::time_point now) {
  const ClientLimits& limits = info_.limits;
  if (limits.add_rights == AddRights::nobody)
    return refuse(wire::ErrorCode::not_permitted, "nobody may add balls on this server (--add-rights nobody); ignored",
                  /*disconnect=*/false);
  if (limits.add_rights == AddRights::players && !has_player_)
    return refuse(wire::ErrorCode::not_permitted,
                  "only clients with a player sphere may add balls on this server (--add-rights players); ignored",
                  /*disconnect=*/false);
  const auto allowed = static_cast<std::uint32_t>(std::min<double>(count, balls_.available(now)));
  Outcome out;
  if (allowed < count)
    out = refuse(wire::ErrorCode::rate_limited,
                 "added at most " + std::to_string(allowed) + " of " + std::to_string(count) +
                     " balls: each client may add " + std::to_string(std::lround(limits.add_balls_per_minute)) +
                     " a minute (--add-rate)",
                 /*disconnect=*/false);
  if (allowed > 0 && balls_.take(allowed, now)) out.command = Command{client_id_, AddBallsCommand{allowed}};
  return out;
}

std::optional<ClientProtocol::Clock::time_point> ClientProtocol::player_idle_deadline() const {
  if (!has_player_ || info_.limits.player_idle_s <= 0.0) return std::nullopt;
  return last_used_ + limit_duration(info_.limits.player_idle_s);
}

Outcome ClientProtocol::on_player_idle() {
  has_player_ = false;
  Outcome out = refuse(wire::ErrorCode::player_idle,
                       "your player sphere did not move, and you sent no control, for " +
                           seconds_text(info_.limits.player_idle_s) +
                           " (--player-idle); it was freed for others and you are observing now",
                       /*disconnect=*/false);
  // Leave removes only the sphere; the connection stays.
  out.command = Command{client_id_, LeaveCommand{}};
  return out;
}

Outcome ClientProtocol::on_hello_timeout() {
  return refuse(wire::ErrorCode::hello_timeout,
                "no complete Hello within " + seconds_text(info_.limits.hello_timeout_s) + " (--hello-timeout)",
                /*disconnect=*/true);
}

Outcome ClientProtocol::on_write_stalled(bool sent_meanwhile) {
  return idle_refusal(sent_meanwhile, "read nothing", "sent nor read anything");
}

Outcome ClientProtocol::on_acks_stopped(bool sent_meanwhile) {
  return idle_refusal(sent_meanwhile, "answered no snapshot", "answered a snapshot nor sent anything");
}

Outcome ClientProtocol::idle_refusal(bool sent_meanwhile, const std::string& did, const std::string& neither) {
  const std::string idle = " for " + seconds_text(info_.limits.idle_timeout_s) + " (--idle-timeout)";
  if (sent_meanwhile) return refuse(wire::ErrorCode::too_slow, "the client " + did + idle, /*disconnect=*/true);
  return refuse(wire::ErrorCode::idle_timeout, "the client neither " + neither + idle, /*disconnect=*/true);
}

Outcome ClientProtocol::on_replies_piling_up(std::size_t unsent) {
  return refuse(wire::ErrorCode::too_slow,
                "the client does not read its replies (" + std::to_string(unsent) + " unsent)", /*disconnect=*/true);
}

Outcome ClientProtocol::on_evicted(const std::string& why) {
  return refuse(wire::ErrorCode::server_full, why, /*disconnect=*/true);
}

Outcome ClientProtocol::on_server_stopping(const std::string& why) {
  return refuse(wire::ErrorCode::server_stopping, "the server is stopping: " + why, /*disconnect=*/true);
}

Outcome ClientProtocol::on_reply(const Reply& reply) {
  Outcome out;
  if (const auto* joined = std::get_if<JoinedReply>(&reply.result)) {
    protocol::WelcomeInfo w;
    w.client_id = client_id_;
    w.server_variant = info_.variant;
    w.simd_level = info_.simd;
    w.worker_threads = info_.worker_threads;
    w.tank = info_.tank;
    w.dt = info_.dt;
    w.steps_per_contact = info_.steps_per_contact;
    w.tolerance = info_.tolerance;
    w.player_id = joined->player_id;
    w.snapshot_rate_hz = info_.snapshot_rate_hz;
    has_player_ = joined->player_id.has_value();
    w.control_policy = describe(info_.control);
    w.may_control = may_control(info_.control, has_player_);
    w.observers_may_control = may_control(info_.control, false);
    out.replies.push_back(protocol::encode_welcome(w));
    last_used_ = Clock::now();
    if (!joined->refusal.empty())
      out.replies.push_back(protocol::encode_error(wire::ErrorCode::player_limit, joined->refusal));
    out.log = joined->player_id
                  ? "welcomed with player sphere " + std::to_string(*joined->player_id)
                  : "welcomed as observer" + (joined->refusal.empty() ? "" : " (" + joined->refusal + ")");
    state_ = State::active;
    return out;
  }
  if (const auto* granted = std::get_if<PlayerGrantedReply>(&reply.result)) {
    has_player_ = true;
    last_used_ = Clock::now();
    out.replies.push_back(protocol::encode_player_granted(granted->player_id, may_control(info_.control, true)));
    out.log = "given player sphere " + std::to_string(granted->player_id) + ", freed by another client";
    return out;
  }
  if (const auto* in_line = std::get_if<InLineReply>(&reply.result)) {
    out.replies.push_back(protocol::encode_in_line(in_line->ahead));
    return out;
  }
  if (const auto* control = std::get_if<ControlRefusedReply>(&reply.result)) {
    using Why = ControlRefusedReply::Why;
    const wire::ErrorCode code = control->why == Why::not_paused    ? wire::ErrorCode::not_paused
                                 : control->why == Why::fewer_balls ? wire::ErrorCode::tank_full
                                 : control->why == Why::superseded  ? wire::ErrorCode::superseded
                                                                    : wire::ErrorCode::server_busy;
    return refuse(code, control->refusal, /*disconnect=*/false);
  }
  const auto& added = std::get<BallsAddedReply>(reply.result);
  if (added.refusal.empty()) return out;
  // World::add_balls's refusal already says how many were added and why no more.
  return refuse(wire::ErrorCode::tank_full, added.refusal, /*disconnect=*/false);
}

Outcome ClientProtocol::on_queue_full() {
  return refuse(wire::ErrorCode::server_busy, "the physics thread is behind on commands; command dropped, try again",
                /*disconnect=*/false);
}

}  // namespace fishtank::net
