// libFuzzer target: arbitrary bytes as a client's byte stream to the server,
// as a WebSocket client's messages to the server, and as a server's byte
// stream to a client.
//
//   bytes ─► FrameReader(to_server) ─► ClientProtocol::on_frame ─► replies, commands
//        │                                 └ on_reply(Joined / BallsAdded) after a Join,
//        │                                   then snapshots sent (some skipped), so Acks count
//        ├─► messages of one chunk each ─► ClientProtocol::on_unprefixed_frame (the
//        │                                 WebSocket path: frames without length prefix) ─► the same
//        └─► FrameReader(to_client) ─► every field a client reads, and the positions
//                                      of every Snapshot (deltas against the ones before)
//
// The first byte picks the chunk size the stream is cut into, so frame
// boundaries land everywhere (and the WebSocket messages have every size up to
// past the 1 KiB allowed before Hello). A crash, a sanitizer report or an
// accepted frame that fails to decode again is a bug.

#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "protocol/frame_codec.h"
#include "protocol/received_snapshots.h"
#include "server/net/client_protocol.h"

using namespace fishtank;

namespace {

// Everyone may use the controls, so the fuzzer reaches them. Named fields: a field added to ServerInfo
// cannot shift the others.
net::ServerInfo fuzzed_server() {
  net::ServerInfo info;
  info.variant = "sse";
  info.simd = "sse4.1";
  info.worker_threads = 2;
  info.dt = 0.001f;
  info.snapshot_rate_hz = 60.0f;
  info.control = ControlPolicy::everyone;
  return info;
}
const net::ServerInfo kInfo = fuzzed_server();

void check(bool ok) {
  if (!ok) std::abort();
}

// What the server does with an outcome, checked; false once the conversation is over.
bool carry_out(net::ClientProtocol& conversation, const net::Outcome& outcome) {
  for (const protocol::Frame& reply : outcome.replies)  // everything the server says must decode
    check(protocol::decode_frame(reply.data(), reply.size(), protocol::Direction::to_client).ok());
  if (outcome.command && std::holds_alternative<net::JoinCommand>(outcome.command->action)) {
    net::Reply joined{1, net::JoinedReply{std::nullopt, "all player spheres are taken"}};
    for (const protocol::Frame& reply : conversation.on_reply(joined).replies)
      check(protocol::decode_frame(reply.data(), reply.size(), protocol::Direction::to_client).ok());
    // Ticks 0 .. 39 sent, every fifth skipped: acks may be good, skipped, too old or in the future.
    for (std::uint32_t tick = 0; tick < 40; ++tick)
      if (tick % 5 != 4) conversation.on_snapshot_sent(tick, 1000);
  }
  return !outcome.disconnect;
}

void drive_server(const std::uint8_t* data, std::size_t size, std::size_t chunk) {
  protocol::FrameReader reader(protocol::Direction::to_server);
  net::ClientProtocol conversation(1, kInfo);
  for (std::size_t at = 0; at < size; at += chunk) {
    reader.append(data + at, std::min(chunk, size - at));
    while (auto decoded = reader.next()) {
      const protocol::Frame& frame = reader.frame();
      // bad_length comes from the prefix alone: there is no frame to hand over.
      const net::Outcome outcome = decoded->status == protocol::DecodeStatus::bad_length
                                       ? conversation.on_broken_stream(*decoded)
                                       : conversation.on_frame(frame.data(), frame.size());
      if (!carry_out(conversation, outcome) || decoded->stream_broken()) return;
    }
  }
}

// The WebSocket path: each chunk is one message, a frame without its length prefix.
void drive_server_websocket(const std::uint8_t* data, std::size_t size, std::size_t chunk) {
  net::ClientProtocol conversation(1, kInfo);
  for (std::size_t at = 0; at < size; at += chunk) {
    // A buffer of its own, as Beast gives WebSession each message, so ASan sees the message's bounds.
    const protocol::Frame message(data + at, data + std::min(size, at + chunk));
    if (!carry_out(conversation, conversation.on_unprefixed_frame(message.data(), message.size()))) return;
  }
}

// Reads every field of an accepted server message, as a client would.
std::uint64_t read_all(const wire::Message& m) {
  std::uint64_t sum = 0;
  if (const auto* s = m.payload_as_Snapshot()) {
    if (s->positions())
      for (std::uint16_t q : *s->positions()) sum += q;
    else
      sum += s->unchanged()->size() + s->changes()->size();
    for (const wire::Vec3f* p : *s->player_positions()) sum += static_cast<std::uint64_t>(p->x() != 0.0f);
    for (std::uint32_t id : *s->player_ids()) sum += id;
  } else if (const auto* k = m.payload_as_BallKinds()) {
    for (std::uint8_t kind : *k->kinds()) sum += kind;
  } else if (const auto* w = m.payload_as_Welcome()) {
    for (const wire::BallKindInfo* kind : *w->ball_kinds()) sum += kind->r();
    sum += w->server_variant()->size() + w->simd_level()->size() + (w->tank_min()->x() < 0.0f);
  } else if (const auto* e = m.payload_as_Error()) {
    sum += e->message()->size();
  }
  return sum;
}

void drive_client(const std::uint8_t* data, std::size_t size, std::size_t chunk) {
  protocol::FrameReader reader(protocol::Direction::to_client);
  protocol::ReceivedSnapshots received;
  std::vector<std::uint16_t> positions;
  volatile std::uint64_t sink = 0;
  for (std::size_t at = 0; at < size; at += chunk) {
    reader.append(data + at, std::min(chunk, size - at));
    while (auto decoded = reader.next()) {
      if (decoded->stream_broken()) return;
      if (!decoded->ok()) continue;
      sink = sink + read_all(*decoded->message);
      if (const auto* s = decoded->message->payload_as_Snapshot()) {
        // A delta it cannot rebuild gets a reason; one it can has every ball.
        const std::string why = received.positions(*s, positions);
        check(!why.empty() || positions.size() == 3 * std::size_t{s->ball_count()});
      }
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::size_t chunk = 1 + data[0] % 64 * 17;  // 1 .. 1072 bytes per read
  drive_server(data + 1, size - 1, chunk);
  drive_server_websocket(data + 1, size - 1, chunk);
  drive_client(data + 1, size - 1, chunk);
  return 0;
}
