#include "server/net/session.h"

#include <spdlog/spdlog.h>

namespace fishtank::net {

namespace asio = boost::asio;

Session::Session(const asio::any_io_executor& executor, const asio::ip::tcp::endpoint& peer, std::uint32_t id,
                 const ServerInfo& info, SessionOwner& owner)
    : id_(id),
      owner_(owner),
      protocol_(id, info),
      limits_(info.limits),
      address_(peer.address()),
      peer_(peer.address().to_string() + ":" + std::to_string(peer.port())),
      watchdog_(executor) {}

void Session::start() {
  spdlog::info("client {} connected from {}{}", id_, peer_, transport_label());
  start_transport();
  arm_watchdog();
}

void Session::frame_received(const std::uint8_t* frame, std::size_t size) {
  const bool had_hello = protocol_.hello_received();
  Outcome outcome = protocol_.on_frame(frame, size, last_received_);
  if (!had_hello && protocol_.hello_received()) owner_.session_said_hello(*this);
  carry_out(std::move(outcome));
}

void Session::message_received(const std::uint8_t* body, std::size_t size) {
  const bool had_hello = protocol_.hello_received();
  Outcome outcome = protocol_.on_unprefixed_frame(body, size, last_received_);
  if (!had_hello && protocol_.hello_received()) owner_.session_said_hello(*this);
  carry_out(std::move(outcome));
}

void Session::stream_broken(const protocol::DecodeResult& refused) { carry_out(protocol_.on_broken_stream(refused)); }

void Session::read_on() {
  if (closed_) return;
  if (close_after_write_) return do_drain();
  do_read();
}

void Session::carry_out(Outcome outcome) {
  if (closed_) return;
  if (!outcome.log.empty()) spdlog::info("client {}: {}", id_, outcome.log);
  // One that is ending has queued its last word, an Error: nothing is sent after it.
  if (close_after_write_) return;
  // Join and Leave are always queued, so what is dropped here is a command whose other
  // replies (a partial add's refusal) no longer hold: the refusal replaces them.
  if (outcome.command && !owner_.submit(std::move(*outcome.command))) return carry_out(protocol_.on_queue_full());
  for (protocol::Frame& reply : outcome.replies) replies_.push_back(std::move(reply));
  if (outcome.disconnect) {
    close_after_write_ = true;
    hard_close_at_ = Clock::now() + kErrorGrace;
    arm_watchdog();
  }
  if (replies_.size() > kMaxQueuedReplies && !close_after_write_)
    return carry_out(protocol_.on_replies_piling_up(replies_.size()));
  do_write();
}

void Session::answer_in_kind_and_close(std::vector<std::uint8_t> bytes, const std::string& log) {
  Outcome outcome;
  outcome.replies.push_back(std::move(bytes));
  outcome.disconnect = true;
  outcome.log = log;
  carry_out(std::move(outcome));
}

void Session::offer_snapshot(SharedSnapshot snapshot) {
  if (closed_ || close_after_write_ || !protocol_.welcomed() || !protocol_.watching()) return;
  if (newest_snapshot_) owner_.snapshot_skipped();
  newest_snapshot_ = std::move(snapshot);  // an unsent older one is dropped here
  do_write();
}

void Session::deliver(const Reply& reply) {
  // A Welcome or sphere that reaches a session already ending is neither sent nor counted.
  if (closed_ || close_after_write_) return;
  const bool was_welcomed = protocol_.welcomed(), had_player = protocol_.has_player();
  Outcome outcome = protocol_.on_reply(reply);
  // Counted before carry_out, which may close the session (and so uncount it).
  if (!was_welcomed && protocol_.welcomed()) owner_.session_welcomed(*this);
  // A player sphere's idle deadline starts with the Welcome, or with a sphere given later.
  if ((!was_welcomed && protocol_.welcomed()) || (!had_player && protocol_.has_player())) arm_watchdog();
  carry_out(std::move(outcome));
}

void Session::evict(const std::string& why) {
  // One that is ending has had its Error already: it goes at once.
  if (close_after_write_) return close(why);
  carry_out(protocol_.on_evicted(why));
}

void Session::say_server_stopping(const std::string& why) {
  if (closed_) return;
  // One that is ending has had its last word; one without Hello has no one to tell.
  if (close_after_write_ || !protocol_.hello_received()) return close("server shutting down");
  server_stopping_ = true;
  carry_out(protocol_.on_server_stopping(why));
  if (closed_) return;
  hard_close_at_ = Clock::now() + kStopGrace;
  arm_watchdog();
}

void Session::do_write() {
  if (write_in_flight_ || closed_) return;
  if (!carries_frames()) {
    // Only a connection that has not said Hello cannot carry frames: it has no one to tell why.
    if (close_after_write_) close("disconnected by the server before it upgraded to a WebSocket");
    return;
  }
  std::vector<asio::const_buffer> buffers;
  writing_replies_.assign(std::make_move_iterator(replies_.begin()), std::make_move_iterator(replies_.end()));
  replies_.clear();
  for (const protocol::Frame& reply : writing_replies_) buffers.push_back(asio::buffer(reply));
  // A snapshot held for a queueing link goes with the write after the client's next Ack (carry_out).
  if (newest_snapshot_ && !close_after_write_ && protocol_.may_send_snapshot()) {
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
    writing_snapshot_ = owner_
                            .snapshot_frame(snapshot, protocol_.delta_base(), protocol_.delta_prior(),
                                            [this](std::uint32_t tick) { return protocol_.keeps(tick); })
                            .frame;
    protocol_.on_snapshot_sent(snapshot->header.tick, writing_snapshot_->size());
    buffers.push_back(asio::buffer(*writing_snapshot_));
  }
  if (buffers.empty()) {
    if (close_after_write_ && !farewell_sent_) {
      // Everything is sent: the farewell follows it, and do_drain() waits for the peer's.
      farewell_sent_ = true;
      send_farewell();
    }
    return;
  }
  write_in_flight_ = true;
  write_started_ = Clock::now();
  write_frames(std::move(buffers));
}

void Session::frames_written(const boost::system::error_code& ec, std::size_t bytes) {
  write_in_flight_ = false;
  writing_replies_.clear();
  writing_kinds_.clear();
  writing_snapshot_.reset();
  if (ec) return on_error(ec, "disconnected");
  owner_.bytes_sent(bytes);
  do_write();
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
  if (const auto unanswered = protocol_.oldest_unanswered_snapshot())
    next = std::min(next, *unanswered + limit_duration(limits_.idle_timeout_s));
  if (const auto idle_player = protocol_.player_idle_deadline()) next = std::min(next, *idle_player);
  return next;
}

void Session::check_limits() {
  const Clock::time_point now = Clock::now();
  if (hard_close_at_) {
    if (now >= *hard_close_at_)
      close(farewell_sent_ ? "disconnected by the server; the client had not closed its side within the grace"
                           : "disconnected by the server before it read why");
    return;
  }
  if (!protocol_.hello_received() && now >= connected_at_ + limit_duration(limits_.hello_timeout_s))
    return carry_out(protocol_.on_hello_timeout());
  if (write_in_flight_ && now >= write_started_ + limit_duration(limits_.idle_timeout_s))
    return carry_out(protocol_.on_write_stalled(/*sent_meanwhile=*/last_received_ > write_started_));
  // Snapshots wait for an acknowledging client's Acks (AckTracker), so one that stopped answering stalls no write.
  if (const auto unanswered = protocol_.oldest_unanswered_snapshot();
      unanswered && now >= *unanswered + limit_duration(limits_.idle_timeout_s))
    return carry_out(protocol_.on_acks_stopped(/*sent_meanwhile=*/last_received_ > *unanswered));
  if (const auto idle_player = protocol_.player_idle_deadline(); idle_player && now >= *idle_player)
    carry_out(protocol_.on_player_idle());
}

void Session::on_error(const boost::system::error_code& ec, const char* on_eof) {
  if (ec == asio::error::operation_aborted) return;  // we closed the connection ourselves: not an error
  // Compared by value and category, without building a misc_errors error_code: that calls into
  // Boost's category object, which UBSan caught mid-construction or mid-destruction at exit.
  const bool eof = ec.value() == asio::error::eof && ec.category() == asio::error::get_misc_category();
  close(eof ? on_eof : ec.message());
}

void Session::close(const std::string& reason) {
  if (closed_) return;
  closed_ = true;
  watchdog_.cancel();
  close_transport();
  spdlog::info("client {} ('{}') closed: {}", id_, protocol_.client_name(), reason);
  owner_.session_closed(*this);
}

}  // namespace fishtank::net
