#include "server/net/session.h"

#include <spdlog/spdlog.h>

namespace fishtank::net {

namespace asio = boost::asio;

namespace {
// A frame's buffer starts at this and doubles as its bytes arrive.
constexpr std::size_t kFirstChunkBytes = 4096;

}  // namespace

Session::Session(asio::ip::tcp::socket socket, std::uint32_t id, const ServerInfo& info, SessionOwner& owner)
    : socket_(std::move(socket)),
      id_(id),
      owner_(owner),
      protocol_(id, info),
      limits_(info.limits),
      watchdog_(socket_.get_executor()) {
  boost::system::error_code ec;
  const auto endpoint = socket_.remote_endpoint(ec);
  peer_ = ec ? "unknown peer" : endpoint.address().to_string() + ":" + std::to_string(endpoint.port());
  socket_.set_option(asio::ip::tcp::no_delay(true), ec);  // small replies (Pong) should not wait for Nagle
}

void Session::start() {
  spdlog::info("client {} connected from {}", id_, peer_);
  do_read_header();
  arm_watchdog();
}

void Session::do_read_header() {
  asio::async_read(socket_, asio::buffer(header_),
                   [this, self = shared_from_this()](boost::system::error_code ec, std::size_t) {
                     if (ec) return on_error(ec, "disconnected");
                     last_received_ = Clock::now();
                     if (close_after_write_) return do_drain();
                     std::uint32_t body_bytes = 0;
                     protocol::DecodeResult length = protocol_.check_length_prefix(header_.data(), &body_bytes);
                     if (!length.ok()) {
                       carry_out(protocol_.on_broken_stream(length));
                       return do_drain();
                     }
                     frame_bytes_ = protocol::kLengthPrefixBytes + body_bytes;
                     incoming_.assign(header_.begin(), header_.end());
                     do_read_body();
                   });
}

// The buffer doubles as the bytes come in, so a peer that announces a large
// frame and stalls holds about twice what it actually sent, not what it announced.
void Session::do_read_body() {
  const std::size_t have = incoming_.size();
  const std::size_t chunk = std::min(frame_bytes_ - have, std::max(have, kFirstChunkBytes));
  incoming_.resize(have + chunk);
  asio::async_read(socket_, asio::buffer(incoming_.data() + have, chunk),
                   [this, self = shared_from_this()](boost::system::error_code ec, std::size_t) {
                     if (ec) return on_error(ec, "disconnected mid-frame");
                     last_received_ = Clock::now();
                     if (close_after_write_) return do_drain();
                     if (incoming_.size() < frame_bytes_) return do_read_body();
                     carry_out(protocol_.on_frame(incoming_.data(), incoming_.size(), last_received_));
                     // A large frame's buffer is not kept for the small ones that follow.
                     if (incoming_.capacity() > 4 * kFirstChunkBytes) protocol::Frame().swap(incoming_);
                     if (closed_) return;
                     if (close_after_write_) return do_drain();
                     do_read_header();
                   });
}

// A session that is ending reads and drops what the peer still sends: closing
// with unread bytes would reset the connection, and the peer could lose the
// Error that says why. The peer's close, or the grace period, ends it.
void Session::do_drain() {
  if (closed_) return;
  incoming_.resize(kFirstChunkBytes);
  socket_.async_read_some(asio::buffer(incoming_),
                          [this, self = shared_from_this()](boost::system::error_code ec, std::size_t) {
                            if (ec) return on_error(ec, "disconnected by the server");
                            do_drain();
                          });
}

void Session::carry_out(Outcome outcome) {
  if (closed_) return;
  if (!outcome.log.empty()) spdlog::info("client {}: {}", id_, outcome.log);
  if (outcome.command && !owner_.submit(std::move(*outcome.command))) return carry_out(protocol_.on_queue_full());
  for (protocol::Frame& reply : outcome.replies) replies_.push_back(std::move(reply));
  if (outcome.disconnect && !close_after_write_) {
    close_after_write_ = true;
    hard_close_at_ = Clock::now() + kErrorGrace;
    arm_watchdog();
  }
  if (replies_.size() > kMaxQueuedReplies && !close_after_write_)
    return carry_out(protocol_.on_replies_piling_up(replies_.size()));
  do_write();
}

void Session::offer_snapshot(SharedSnapshot snapshot) {
  if (closed_ || close_after_write_ || !protocol_.welcomed()) return;
  newest_snapshot_ = std::move(snapshot);  // an unsent older one is dropped here
  do_write();
}

void Session::deliver(const Reply& reply) {
  if (closed_) return;
  const bool was_welcomed = protocol_.welcomed();
  Outcome outcome = protocol_.on_reply(reply);
  // Counted before carry_out, which may close the session (and so uncount it).
  if (!was_welcomed && protocol_.welcomed()) {
    owner_.session_welcomed(*this);
    arm_watchdog();  // a player sphere's idle deadline starts now
  }
  carry_out(std::move(outcome));
}

void Session::do_write() {
  if (write_in_flight_ || closed_) return;
  std::vector<asio::const_buffer> buffers;
  writing_replies_.assign(std::make_move_iterator(replies_.begin()), std::make_move_iterator(replies_.end()));
  replies_.clear();
  for (const protocol::Frame& reply : writing_replies_) buffers.push_back(asio::buffer(reply));
  if (newest_snapshot_ && !close_after_write_) {
    const SharedSnapshot snapshot = std::move(newest_snapshot_);
    newest_snapshot_.reset();
    const std::uint32_t balls = snapshot->ball_count;
    if (snapshot->scene_start != scene_start_) {
      scene_start_ = snapshot->scene_start;
      kinds_sent_ = 0;  // new balls, new ids from 0
    }
    if (balls > kinds_sent_) {
      writing_kinds_ =
          protocol::encode_ball_kinds(kinds_sent_, snapshot->kinds_by_id->data() + kinds_sent_, balls - kinds_sent_);
      kinds_sent_ = balls;
      buffers.push_back(asio::buffer(writing_kinds_));
    }
    writing_snapshot_ = owner_.snapshot_frame(snapshot, protocol_.delta_base(), protocol_.delta_prior()).frame;
    protocol_.on_snapshot_sent(snapshot->header.tick);
    buffers.push_back(asio::buffer(*writing_snapshot_));
  }
  if (buffers.empty()) {
    if (close_after_write_ && !farewell_sent_) {
      // Everything is sent: a FIN follows it, and do_drain() waits for the peer's.
      farewell_sent_ = true;
      boost::system::error_code ignored;
      socket_.shutdown(asio::ip::tcp::socket::shutdown_send, ignored);
    }
    return;
  }
  write_in_flight_ = true;
  write_started_ = Clock::now();
  asio::async_write(socket_, buffers, [this, self = shared_from_this()](boost::system::error_code ec, std::size_t n) {
    write_in_flight_ = false;
    writing_replies_.clear();
    writing_kinds_.clear();
    writing_snapshot_.reset();
    if (ec) return on_error(ec, "disconnected");
    owner_.bytes_sent(n);
    do_write();
  });
}

void Session::arm_watchdog() {
  if (closed_) return;
  // Re-arming cancels the pending wait, whose handler then sees operation_aborted.
  watchdog_.expires_at(next_check(Clock::now()));
  watchdog_.async_wait([this, self = shared_from_this()](boost::system::error_code ec) {
    if (ec || closed_) return;
    check_limits();
    arm_watchdog();
  });
}

// Deadlines only move later while a session runs, except those that begin
// (the Welcome's sphere, the grace), which re-arm: waking at the earliest one
// known now is never late.
Session::Clock::time_point Session::next_check(Clock::time_point now) const {
  if (hard_close_at_) return *hard_close_at_;
  Clock::time_point next = (write_in_flight_ ? write_started_ : now) + limit_duration(limits_.idle_timeout_s);
  if (!protocol_.hello_received()) next = std::min(next, connected_at_ + limit_duration(limits_.hello_timeout_s));
  if (const auto idle_player = protocol_.player_idle_deadline()) next = std::min(next, *idle_player);
  return next;
}

void Session::check_limits() {
  const Clock::time_point now = Clock::now();
  if (hard_close_at_) {
    if (now >= *hard_close_at_)
      close(farewell_sent_ ? "disconnected by the server" : "disconnected by the server before it read why");
    return;
  }
  if (!protocol_.hello_received() && now >= connected_at_ + limit_duration(limits_.hello_timeout_s))
    return carry_out(protocol_.on_hello_timeout());
  if (write_in_flight_ && now >= write_started_ + limit_duration(limits_.idle_timeout_s))
    return carry_out(protocol_.on_write_stalled(/*sent_meanwhile=*/last_received_ > write_started_));
  if (const auto idle_player = protocol_.player_idle_deadline(); idle_player && now >= *idle_player)
    carry_out(protocol_.on_player_idle());
}

void Session::on_error(const boost::system::error_code& ec, const char* on_eof) {
  if (ec == asio::error::operation_aborted) return;  // we closed the socket ourselves: not an error
  // Compared by value and category, without building a misc_errors error_code: that calls into
  // Boost's category object, which UBSan caught mid-construction or mid-destruction at exit.
  const bool eof = ec.value() == asio::error::eof && ec.category() == asio::error::get_misc_category();
  close(eof ? on_eof : ec.message());
}

void Session::close(const std::string& reason) {
  if (closed_) return;
  closed_ = true;
  watchdog_.cancel();
  boost::system::error_code ignored;
  socket_.shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
  socket_.close(ignored);
  spdlog::info("client {} ('{}') closed: {}", id_, protocol_.client_name(), reason);
  owner_.session_closed(*this);
}

}  // namespace fishtank::net
