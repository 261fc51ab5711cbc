#include "client/connection.h"

#include <algorithm>
#include <cstdlib>

#include "common/printable_text.h"
#include "common/server_hint.h"
#include "protocol/quantize.h"

namespace fishtank::client {

namespace asio = boost::asio;

Connection::Connection(asio::io_context& io, std::string name, bool wants_player)
    : socket_(io), name_(std::move(name)), wants_player_(wants_player), read_pause_(io) {}

void Connection::start(const asio::ip::tcp::endpoint& server, std::uint32_t version) {
  socket_.async_connect(server, [this, self = shared_from_this(), version](boost::system::error_code ec) {
    if (ec) return fail(ec == asio::error::operation_aborted ? "" : "cannot connect: " + ec.message());
    boost::system::error_code ignored;
    socket_.set_option(asio::ip::tcp::no_delay(true), ignored);
    send(protocol::encode_hello(name_, wants_player_, acknowledge_, version));
    do_read();
  });
}

void Connection::send(protocol::Frame frame) {
  if (closed_) return;
  outgoing_.push_back(std::move(frame));
  do_write();
}

void Connection::send_ping() {
  const auto us = std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - epoch_);
  send(protocol::encode_ping(static_cast<std::uint32_t>(us.count())));
}

void Connection::close(const std::string& reason) {
  if (closed_) return;
  closed_ = true;
  if (close_reason_.empty()) close_reason_ = reason;
  boost::system::error_code ignored;
  socket_.shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
  socket_.close(ignored);
  read_pause_.cancel();
}

void Connection::fail(const std::string& reason) {
  if (close_reason_.empty()) close_reason_ = reason;  // "" (a write aborted by close): close's own
  close();
}

void Connection::do_write() {
  if (write_in_flight_ || outgoing_.empty() || !socket_.is_open()) return;
  write_in_flight_ = true;
  asio::async_write(socket_, asio::buffer(outgoing_.front()),
                    [this, self = shared_from_this()](boost::system::error_code ec, std::size_t) {
                      write_in_flight_ = false;
                      if (ec) return fail(ec == asio::error::operation_aborted ? "" : "write failed: " + ec.message());
                      outgoing_.pop_front();
                      do_write();
                    });
}

void Connection::do_read() {
  // A limited rate reads 20 ms of it at a time, so the bytes arrive as evenly as over a slow link.
  const std::size_t chunk =
      read_rate_ > 0.0 ? std::clamp<std::size_t>(read_rate_ / 50.0, 1024, read_buffer_.size()) : read_buffer_.size();
  socket_.async_read_some(asio::buffer(read_buffer_.data(), chunk),
                          [this, self = shared_from_this()](boost::system::error_code ec, std::size_t n) {
                            if (ec == asio::error::operation_aborted) return fail("");  // close()'s own
                            if (ec)
                              return fail(ec == asio::error::eof ? closed_by_server_text(farewell_) : ec.message());
                            stats_.bytes_received += n;
                            reader_.append(read_buffer_.data(), n);
                            while (std::optional<protocol::DecodeResult> frame = reader_.next()) {
                              if (!frame->ok()) {
                                stats_.errors.push_back("bad frame from the server: " + frame->why);
                                if (frame->stream_broken()) return fail("bad frame from the server: " + frame->why);
                                continue;
                              }
                              handle(*frame->message);
                            }
                            if (closed_) return;
                            if (read_rate_ <= 0.0) return do_read();
                            read_pause_.expires_after(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                std::chrono::duration<double>(n / read_rate_)));
                            read_pause_.async_wait([this, self](boost::system::error_code e) {
                              if (!e && !closed_) do_read();
                            });
                          });
}

void Connection::handle(const wire::Message& message) {
  switch (message.payload_type()) {
    case wire::Payload::Welcome: {
      const wire::Welcome& w = *message.payload_as_Welcome();
      welcomed_ = true;
      if (w.has_player()) player_id_ = w.player_id();
      worker_threads_ = w.worker_threads();
      tank_.min = {w.tank_min()->x(), w.tank_min()->y(), w.tank_min()->z()};
      tank_.max = {w.tank_max()->x(), w.tank_max()->y(), w.tank_max()->z()};
      may_control_ = w.may_control();
      control_policy_ = w.control_policy() ? server_text(w.control_policy()->str()) : std::string();
      break;
    }
    case wire::Payload::BallKinds: {
      const wire::BallKinds& k = *message.payload_as_BallKinds();
      // Earlier than expected is a scene's new start (kinds from there on are replaced); later is a gap.
      if (k.first_new_ball() > view_.kinds.size())
        stats_.errors.push_back("BallKinds starts at ball " + std::to_string(k.first_new_ball()) + ", expected " +
                                std::to_string(view_.kinds.size()) + " at most");
      view_.kinds.resize(k.first_new_ball());
      view_.kinds.insert(view_.kinds.end(), k.kinds()->begin(), k.kinds()->end());
      stats_.kinds_received += k.kinds()->size();
      break;
    }
    case wire::Payload::Snapshot:
      on_snapshot(*message.payload_as_Snapshot());
      break;
    case wire::Payload::Error: {
      const wire::Error& e = *message.payload_as_Error();
      stats_.error_codes.push_back(protocol::error_code_name(e.code()));
      stats_.errors.push_back(stats_.error_codes.back() + ": " + server_text(e.message()->str()));
      if (protocol::ends_connection(e.code())) farewell_ = stats_.errors.back();
      if (e.code() == wire::ErrorCode::player_idle) player_id_.reset();  // the sphere was freed
      break;
    }
    case wire::Payload::PlayerGranted: {
      const wire::PlayerGranted& g = *message.payload_as_PlayerGranted();
      player_id_ = g.player_id();
      may_control_ = g.may_control();
      ahead_in_line_.reset();
      stats_.player_granted = true;
      break;
    }
    case wire::Payload::InLine:
      ahead_in_line_ = message.payload_as_InLine()->ahead();
      break;
    case wire::Payload::Pong: {
      const auto now_us = static_cast<std::uint32_t>(
          std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - epoch_).count());
      stats_.rtt_ms.push_back(1e-3 * static_cast<std::uint32_t>(now_us - message.payload_as_Pong()->client_time_us()));
      break;
    }
    default:  // decode_frame accepts only server messages in this direction
      break;
  }
}

void Connection::on_snapshot(const wire::Snapshot& s) {
  if (std::string why = received_.positions(s, decoded_); !why.empty()) {
    stats_.errors.push_back(why);
    if (acknowledge_) send(protocol::encode_ack(s.tick(), /*want_keyframe=*/true));
    return;
  }
  if (acknowledge_) send(protocol::encode_ack(s.tick()));
  if (s.ball_count() > view_.kinds.size())
    stats_.errors.push_back("Snapshot has " + std::to_string(s.ball_count()) + " balls but kinds of only " +
                            std::to_string(view_.kinds.size()) + " were sent");
  stats_.keyframes += s.unchanged() == nullptr;
  view_.tick = s.tick();
  view_.sim_time = s.sim_time();
  view_.steps_per_s = s.steps_per_s();
  view_.load = s.load();
  view_.threads_stepping = s.threads_stepping();
  view_.time_scale = s.time_scale();
  view_.ball_count = s.ball_count();
  view_.physics_steps = s.physics_steps();
  view_.paused = s.paused();
  view_.time_scale_set = s.time_scale_set();
  view_.scene = s.scene() ? server_text(s.scene()->str()) : std::string();
  if (s.scene_start() != view_.scene_start) view_.positions.clear();  // other balls: nothing to compare
  view_.scene_start = s.scene_start();
  view_.max_overlap = s.max_overlap();
  if (s.tank_min()) {  // decode_frame checked that both are present and ordered
    tank_.min = {s.tank_min()->x(), s.tank_min()->y(), s.tank_min()->z()};
    tank_.max = {s.tank_max()->x(), s.tank_max()->y(), s.tank_max()->z()};
  }
  const std::size_t common = std::min(view_.positions.size(), decoded_.size()) / 3;
  std::size_t at_rest = 0, small = 0;
  for (std::size_t b = 0; b < common; ++b) {
    int largest = 0;
    for (std::size_t axis = 0; axis < 3; ++axis)
      largest = std::max(largest, std::abs(int{decoded_[3 * b + axis]} - int{view_.positions[3 * b + axis]}));
    at_rest += largest == 0;
    small += largest <= 127;
  }
  stats_.at_rest_fraction = common ? static_cast<double>(at_rest) / common : 0.0;
  stats_.int8_delta_fraction = common ? static_cast<double>(small) / common : 0.0;
  view_.positions.swap(decoded_);
  view_.player_ids.clear();
  view_.player_positions.clear();
  if (s.player_ids())
    for (std::uint32_t i = 0; i < s.player_ids()->size(); ++i) {
      const wire::Vec3f* p = s.player_positions()->Get(i);
      view_.player_ids.push_back(s.player_ids()->Get(i));
      view_.player_positions.push_back({p->x(), p->y(), p->z()});
    }
  const auto now = std::chrono::steady_clock::now();
  if (!stats_.first_snapshot) stats_.first_snapshot = now;
  stats_.last_snapshot = now;
  ++stats_.snapshots;
}

std::optional<Vec3> Connection::player_position(std::uint32_t player_id) const {
  for (std::size_t i = 0; i < view_.player_ids.size(); ++i)
    if (view_.player_ids[i] == player_id) return view_.player_positions[i];
  return std::nullopt;
}

Vec3 Connection::ball_position(std::uint32_t ball_id) const {
  return protocol::dequantize_position(&view_.positions.at(3 * std::size_t{ball_id}), tank_);
}

}  // namespace fishtank::client
