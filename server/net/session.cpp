#include "server/net/session.h"

#include <spdlog/spdlog.h>

namespace fishtank::net {

namespace asio = boost::asio;

Session::Session(asio::ip::tcp::socket socket, std::uint32_t id, const ServerInfo& info, SessionOwner& owner)
    : socket_(std::move(socket)), id_(id), owner_(owner), protocol_(id, info) {
  boost::system::error_code ec;
  const auto endpoint = socket_.remote_endpoint(ec);
  peer_ = ec ? "unknown peer" : endpoint.address().to_string() + ":" + std::to_string(endpoint.port());
  socket_.set_option(asio::ip::tcp::no_delay(true), ec);  // small replies (Pong) should not wait for Nagle
}

void Session::start() {
  spdlog::info("client {} connected from {}", id_, peer_);
  do_read_header();
}

void Session::do_read_header() {
  asio::async_read(socket_, asio::buffer(header_),
                   [this, self = shared_from_this()](boost::system::error_code ec, std::size_t) {
                     if (ec) return on_error(ec, "disconnected");
                     std::uint32_t body_bytes = 0;
                     protocol::DecodeResult length =
                         protocol::check_length_prefix(header_.data(), protocol::Direction::to_server, &body_bytes);
                     if (!length.ok()) return carry_out(protocol_.on_broken_stream(length));
                     do_read_body(body_bytes);
                   });
}

void Session::do_read_body(std::uint32_t body_bytes) {
  // Allocated only now that the length is known to be within kMaxClientFrameBytes.
  incoming_.resize(protocol::kLengthPrefixBytes + body_bytes);
  std::copy(header_.begin(), header_.end(), incoming_.begin());
  asio::async_read(socket_, asio::buffer(incoming_.data() + protocol::kLengthPrefixBytes, body_bytes),
                   [this, self = shared_from_this()](boost::system::error_code ec, std::size_t) {
                     if (ec) return on_error(ec, "disconnected mid-frame");
                     carry_out(protocol_.on_frame(incoming_.data(), incoming_.size()));
                     if (!close_after_write_ && !closed_) do_read_header();
                   });
}

void Session::carry_out(Outcome outcome) {
  if (closed_) return;
  if (!outcome.log.empty()) spdlog::info("client {}: {}", id_, outcome.log);
  if (outcome.command && !owner_.submit(std::move(*outcome.command))) return carry_out(protocol_.on_queue_full());
  for (protocol::Frame& reply : outcome.replies) replies_.push_back(std::move(reply));
  if (replies_.size() > kMaxQueuedReplies)
    return close("not reading its replies (" + std::to_string(replies_.size()) + " unsent)");
  if (outcome.disconnect) close_after_write_ = true;
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
  if (!was_welcomed && protocol_.welcomed()) owner_.session_welcomed(*this);
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
    if (close_after_write_) close("disconnected by the server");
    return;
  }
  write_in_flight_ = true;
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

void Session::on_error(const boost::system::error_code& ec, const char* on_eof) {
  if (ec == asio::error::operation_aborted) return;  // we closed the socket ourselves: not an error
  close(ec == asio::error::eof ? on_eof : ec.message());
}

void Session::close(const std::string& reason) {
  if (closed_) return;
  closed_ = true;
  boost::system::error_code ignored;
  socket_.shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
  socket_.close(ignored);
  spdlog::info("client {} ('{}') closed: {}", id_, protocol_.client_name(), reason);
  owner_.session_closed(*this);
}

}  // namespace fishtank::net
