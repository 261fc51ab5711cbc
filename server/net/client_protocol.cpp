#include "server/net/client_protocol.h"

#include <cstdio>

namespace fishtank::net {

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

Outcome ClientProtocol::on_frame(const std::uint8_t* frame, std::size_t size) {
  const protocol::DecodeResult decoded = protocol::decode_frame(frame, size, protocol::Direction::to_server);
  if (decoded.stream_broken()) return on_broken_stream(decoded);
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
  return on_message(*decoded.message);
}

std::string printable_name(const std::string& raw) {
  std::string name;
  for (std::size_t i = 0; i < raw.size() && i < kMaxNameBytes; ++i) {
    const auto c = static_cast<unsigned char>(raw[i]);
    if (c >= 0x20 && c < 0x7f && c != '\\') {
      name += static_cast<char>(c);
    } else {
      char escaped[5];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", c);
      name += escaped;
    }
  }
  if (raw.size() > kMaxNameBytes) name += "...";
  return name;
}

Outcome ClientProtocol::on_hello(const wire::Hello& hello) {
  if (hello.client_name()) name_ = printable_name(hello.client_name()->str());
  if (hello.protocol_version() != protocol::kProtocolVersion)
    return refuse(wire::ErrorCode::version_mismatch,
                  "this server speaks protocol version " + std::to_string(protocol::kProtocolVersion) +
                      ", the client speaks version " + std::to_string(hello.protocol_version()) +
                      "; use a client and server from the same release",
                  /*disconnect=*/true);
  state_ = State::joining;
  Outcome out;
  out.command = Command{client_id_, JoinCommand{hello.wants_player()}};
  out.log = "hello from '" + name_ + "'" + (hello.wants_player() ? ", wants a player sphere" : ", observing");
  return out;
}

Outcome ClientProtocol::on_message(const wire::Message& message) {
  Outcome out;
  switch (message.payload_type()) {
    case wire::Payload::Hello:
      return refuse(wire::ErrorCode::unexpected_message, "Hello was already received; message ignored", false);
    case wire::Payload::PlayerInput: {
      const wire::Vec3f& v = *message.payload_as_PlayerInput()->velocity();
      out.command = Command{client_id_, SetVelocityCommand{{v.x(), v.y(), v.z()}}};
      return out;
    }
    case wire::Payload::AddBalls:
      out.command = Command{client_id_, AddBallsCommand{message.payload_as_AddBalls()->count()}};
      return out;
    case wire::Payload::Ping:
      out.replies.push_back(protocol::encode_pong(message.payload_as_Ping()->client_time_us()));
      return out;
    case wire::Payload::Ack: {
      const wire::Ack& ack = *message.payload_as_Ack();
      if (std::string why = acks_.acknowledged(ack.tick(), ack.want_keyframe()); !why.empty())
        return refuse(wire::ErrorCode::invalid_value, why, /*disconnect=*/false);
      return out;
    }
    default:  // decode_frame accepts nothing else in this direction
      return refuse(wire::ErrorCode::unexpected_message, "message type not accepted by the server", false);
  }
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
    w.player_id = joined->player_id;
    w.snapshot_rate_hz = info_.snapshot_rate_hz;
    out.replies.push_back(protocol::encode_welcome(w));
    if (!joined->refusal.empty())
      out.replies.push_back(protocol::encode_error(wire::ErrorCode::player_limit, joined->refusal));
    out.log = joined->player_id
                  ? "welcomed with player sphere " + std::to_string(*joined->player_id)
                  : "welcomed as observer" + (joined->refusal.empty() ? "" : " (" + joined->refusal + ")");
    state_ = State::active;
    return out;
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
