#include "viewer/net/client.h"

#include <chrono>
#include <cstring>

#include "common/host_port.h"
#include "common/printable_text.h"
#include "common/server_hint.h"
#include "viewer/clock.h"

namespace fishtank::viewer {
namespace asio = boost::asio;
using tcp = asio::ip::tcp;
using boost::system::error_code;

namespace {

constexpr auto kRetryDelay = std::chrono::seconds(1);
constexpr auto kInputPeriod = std::chrono::microseconds(1'000'000 / 30);  // 30 Hz
// Frames waiting to be sent. More means the server is not reading us; it will
// say so (too_slow) and disconnect, and nothing queued is worth keeping.
constexpr std::size_t kMaxQueuedFrames = 64;

Vec3 to_vec3(const wire::Vec3f& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

NetClient::NetClient(std::string host, std::string port, bool wants_player, SnapshotBuffer& snapshots)
    : host_(std::move(host)), port_(std::move(port)), wants_player_(wants_player), snapshots_(snapshots) {
  status_.endpoint = host_port_text(host_, port_);
  ping_epoch_ = second_started_ = steady_seconds();
  asio::post(io_, [this] {
    do_connect();
    input_timer_.expires_after(kInputPeriod);
    input_timer_.async_wait([this](error_code ec) {
      if (!ec) every_input_tick();
    });
    second_timer_.expires_after(std::chrono::seconds(1));
    second_timer_.async_wait([this](error_code ec) {
      if (!ec) every_second();
    });
  });
  thread_ = std::thread([this] { io_.run(); });
}

NetClient::~NetClient() {
  io_.stop();
  thread_.join();
}

void NetClient::set_velocity(Vec3 velocity) {
  std::lock_guard lock(velocity_mutex_);
  velocity_ = velocity;
}

void NetClient::add_balls(std::uint32_t count) {
  asio::post(io_, [this, count] {
    if (connected_) send(protocol::encode_add_balls(count));
  });
}

void NetClient::set_watching(bool on) {
  asio::post(io_, [this, on] {
    if (on == watching_) return;
    watching_ = on;
    if (connected_) send(protocol::encode_watching(on));
  });
}

void NetClient::change_info(const std::function<void(ServerInfo&)>& change, std::string notice) {
  auto changed = std::make_shared<ServerInfo>(*info_);
  change(*changed);
  info_ = changed;
  update_status([&](ConnectionStatus& s) {
    s.info = info_;
    if (notice.empty()) return;
    s.notice = std::move(notice);
    s.notice_time = steady_seconds();
  });
}

void NetClient::send_command(protocol::Frame frame) {
  asio::post(io_, [this, frame = std::move(frame)]() mutable {
    if (connected_) send(std::move(frame));
  });
}

ConnectionStatus NetClient::status() const {
  std::lock_guard lock(status_mutex_);
  return status_;
}

void NetClient::do_connect() {
  update_status([](ConnectionStatus& s) {
    s.state = ConnectionStatus::State::connecting;
    ++s.attempts;
  });
  const std::uint64_t gen = generation_;
  resolver_.async_resolve(
      host_, port_, [this, gen](error_code ec, const tcp::resolver::results_type& results) {
        if (gen != generation_) return;
        if (ec) return lose(cannot_resolve_text(host_, ec.message()));
        asio::async_connect(socket_, results, [this, gen](error_code connect_ec, const tcp::endpoint&) {
          if (gen != generation_) return;
          if (connect_ec) return lose("cannot connect: " + connect_ec.message());
          error_code ignored;
          socket_.set_option(tcp::no_delay(true), ignored);  // small inputs go out at once
          send(protocol::encode_hello("fishtank-viewer", wants_player_, /*acknowledges=*/true));
          do_read_prefix();
        });
      });
}

void NetClient::lose(const std::string& why) {
  ++generation_;
  farewell_.clear();
  error_code ignored;
  socket_.close(ignored);
  write_queue_.clear();
  connected_ = false;
  update_status([&](ConnectionStatus& s) {
    s.state = ConnectionStatus::State::lost;
    s.last_error = why;
    s.rtt_ms = -1.0f;
  });
  // The last picture stays on screen (marked lost) until a new Welcome.
  retry_timer_.expires_after(kRetryDelay);
  retry_timer_.async_wait([this](error_code ec) {
    if (!ec) do_connect();
  });
}

void NetClient::do_read_prefix() {
  const std::uint64_t gen = generation_;
  asio::async_read(socket_, asio::buffer(prefix_), [this, gen](error_code ec, std::size_t) {
    if (gen != generation_) return;
    if (ec == asio::error::eof) return lose(closed_by_server_text(farewell_));
    if (ec) return lose("receive failed: " + ec.message());
    std::uint32_t body_bytes = 0;
    protocol::DecodeResult r =
        protocol::check_length_prefix(prefix_, protocol::Direction::to_client, &body_bytes);
    if (!r.ok()) return lose("bad frame from the server: " + r.why);
    do_read_body(body_bytes);
  });
}

void NetClient::do_read_body(std::uint32_t body_bytes) {
  // The frame keeps its prefix: decode_frame checks the whole thing. The
  // vector's capacity is reused, so steady snapshots allocate nothing here.
  frame_.resize(protocol::kLengthPrefixBytes + body_bytes);
  std::memcpy(frame_.data(), prefix_, protocol::kLengthPrefixBytes);
  const std::uint64_t gen = generation_;
  asio::async_read(socket_, asio::buffer(frame_.data() + protocol::kLengthPrefixBytes, body_bytes),
                   [this, gen](error_code ec, std::size_t) {
                     if (gen != generation_) return;
                     if (ec) return lose("receive failed: " + ec.message());
                     bytes_this_second_ += frame_.size();
                     on_frame();
                     if (gen == generation_) do_read_prefix();
                   });
}

void NetClient::send(protocol::Frame frame) {
  if (write_queue_.size() >= kMaxQueuedFrames) return;
  write_queue_.push_back(std::move(frame));
  if (write_queue_.size() == 1) do_write();
}

void NetClient::do_write() {
  const std::uint64_t gen = generation_;
  asio::async_write(socket_, asio::buffer(write_queue_.front()), [this, gen](error_code ec, std::size_t) {
    if (gen != generation_) return;
    if (ec) return lose("send failed: " + ec.message());
    write_queue_.pop_front();
    if (!write_queue_.empty()) do_write();
  });
}

void NetClient::on_frame() {
  protocol::DecodeResult r =
      protocol::decode_frame(frame_.data(), frame_.size(), protocol::Direction::to_client);
  if (r.stream_broken()) return lose("bad frame from the server: " + r.why);
  if (!r.ok()) {
    update_status([&](ConnectionStatus& s) {
      s.notice = "ignored a message from the server: " + r.why;
      s.notice_time = steady_seconds();
    });
    return;
  }
  const wire::Message& m = *r.message;
  switch (m.payload_type()) {
    case wire::Payload::Welcome:
      return on_welcome(*m.payload_as_Welcome());
    case wire::Payload::BallKinds:
      if (!connected_) return lose("the server sent ball kinds before Welcome");
      return on_ball_kinds(*m.payload_as_BallKinds());
    case wire::Payload::Snapshot:
      if (!connected_) return lose("the server sent a snapshot before Welcome");
      return on_snapshot(*m.payload_as_Snapshot());
    case wire::Payload::Error: {
      const wire::Error& e = *m.payload_as_Error();
      const std::string text = server_text(e.message()->str());  // present: decode_frame checks
      if (protocol::ends_connection(e.code())) farewell_ = protocol::error_code_name(e.code()) + ": " + text;
      // Why this viewer observes stays on the HUD's Player row, not only for a notice's few seconds.
      if (info_ && (e.code() == wire::ErrorCode::player_limit || e.code() == wire::ErrorCode::player_idle))
        return change_info(
            [&](ServerInfo& info) {
              info.observing = text;
              // The sphere was freed: from now on this viewer observes, and may control as observers may.
              if (e.code() == wire::ErrorCode::player_idle) {
                info.has_player = false;
                info.may_control = info.observers_may_control;
              }
            },
            "server: " + text);
      return update_status([&](ConnectionStatus& s) {
        s.notice = "server: " + text;
        s.notice_time = steady_seconds();
      });
    }
    case wire::Payload::PlayerGranted: {
      if (!connected_) return lose("the server granted a player sphere before Welcome");
      // Another client's sphere was freed and this viewer, in line for one, has it now.
      const wire::PlayerGranted& g = *m.payload_as_PlayerGranted();
      return change_info(
          [&](ServerInfo& info) {
            info.has_player = true;
            info.observing.clear();
            info.ahead_in_line.reset();
            info.player_id = g.player_id();
            info.may_control = g.may_control();
          },
          "server: a player sphere was freed and is yours now (the white one with the amber ring)");
    }
    case wire::Payload::InLine:
      if (!connected_) return lose("the server gave a place in line before Welcome");
      return change_info([&](ServerInfo& info) { info.ahead_in_line = m.payload_as_InLine()->ahead(); });
    case wire::Payload::Pong: {
      auto now_us = static_cast<std::uint32_t>((steady_seconds() - ping_epoch_) * 1e6);
      std::uint32_t rtt_us = now_us - m.payload_as_Pong()->client_time_us();  // modulo 2^32
      return update_status([&](ConnectionStatus& s) { s.rtt_ms = static_cast<float>(rtt_us) * 1e-3f; });
    }
    default:
      return;  // decode_frame admits only the server's messages
  }
}

void NetClient::on_welcome(const wire::Welcome& w) {
  if (w.protocol_version() != protocol::kProtocolVersion)
    return lose("the server speaks protocol " + std::to_string(w.protocol_version()) + ", this viewer " +
                std::to_string(protocol::kProtocolVersion));
  auto info = std::make_shared<ServerInfo>();
  info->variant = server_text(w.server_variant()->str());  // present: decode_frame checks
  info->simd = server_text(w.simd_level()->str());
  info->threads = static_cast<int>(w.worker_threads());
  info->tank = {to_vec3(*w.tank_min()), to_vec3(*w.tank_max())};  // present: decode_frame checks
  info->dt = w.dt();
  info->steps_per_contact = w.steps_per_contact();
  info->tolerance = w.tolerance();
  for (const wire::BallKindInfo* k : *w.ball_kinds())
    info->kinds.push_back({k->diameter(), k->mass(), {k->r(), k->g(), k->b()}});
  info->client_id = w.client_id();
  info->has_player = w.has_player();
  info->player_id = w.player_id();
  info->control_policy =
      w.control_policy() ? server_text(w.control_policy()->str()) : "not stated by the server";
  info->may_control = w.may_control();
  info->observers_may_control = w.observers_may_control();
  info_ = info;
  kinds_ = std::make_shared<std::vector<std::uint8_t>>();
  received_.clear();
  connected_ = true;
  if (!watching_) send(protocol::encode_watching(false));  // a new connection starts on
  snapshots_.clear();
  update_status([&](ConnectionStatus& s) {
    s.state = ConnectionStatus::State::connected;
    s.attempts = 0;
    s.last_error.clear();
    s.info = info;
  });
}

void NetClient::on_ball_kinds(const wire::BallKinds& k) {
  // Earlier than the kinds known: a scene started again and ids restart; later: a gap.
  if (k.first_new_ball() > kinds_->size()) return lose("the server skipped ball kinds");
  // Copy on write: snapshots already handed to the render thread keep the old list.
  auto kinds =
      std::make_shared<std::vector<std::uint8_t>>(kinds_->begin(), kinds_->begin() + k.first_new_ball());
  for (std::uint8_t kind : *k.kinds()) {
    if (kind >= info_->kinds.size())
      return lose("the server sent ball kind " + std::to_string(kind) + ", unknown");
    kinds->push_back(kind);
  }
  kinds_ = std::move(kinds);
}

void NetClient::on_snapshot(const wire::Snapshot& s) {
  if (s.ball_count() > kinds_->size()) return lose("the server sent balls of unknown kind");
  auto snap = std::make_shared<Snapshot>();
  if (std::string why = received_.positions(s, snap->quantised); !why.empty()) {
    send(protocol::encode_ack(s.tick(), /*want_keyframe=*/true));
    return update_status([&](ConnectionStatus& st) {
      st.notice = why + "; asked for a keyframe";
      st.notice_time = steady_seconds();
    });
  }
  send(protocol::encode_ack(s.tick()));
  snap->tick = s.tick();
  snap->sim_time = s.sim_time();
  snap->received = steady_seconds();
  snap->steps_per_s = s.steps_per_s();
  snap->load = s.load();
  snap->threads_stepping = s.threads_stepping();
  snap->time_scale = s.time_scale();
  snap->paused = s.paused();
  snap->time_scale_set = s.time_scale_set();
  snap->scene = s.scene() ? server_text(s.scene()->str()) : std::string();
  snap->scene_start = s.scene_start();
  snap->kinetic_energy_per_ball = s.kinetic_energy_per_ball();
  snap->contacts = s.contacts();
  snap->max_overlap = s.max_overlap();
  snap->tank = s.tank_min() ? TankBounds{to_vec3(*s.tank_min()), to_vec3(*s.tank_max())} : info_->tank;
  snap->ball_count = s.ball_count();
  snap->kinds = kinds_;
  if (s.player_ids())
    for (flatbuffers::uoffset_t i = 0; i < s.player_ids()->size(); ++i)
      snap->players.push_back({s.player_ids()->Get(i), to_vec3(*s.player_positions()->Get(i))});
  // Other balls under the same ids: nothing to blend with the old scene's.
  if (const auto last = snapshots_.newest(); last && last->scene_start != snap->scene_start)
    snapshots_.clear();
  snapshots_.push(std::move(snap));
  ++snapshots_this_second_;
}

void NetClient::every_input_tick() {
  if (connected_ && info_->has_player) {
    Vec3 v;
    {
      std::lock_guard lock(velocity_mutex_);
      v = velocity_;
    }
    send(protocol::encode_player_input(++input_sequence_, v));
  }
  // From the previous deadline, not from now: a steady 30 Hz without drift.
  input_timer_.expires_at(input_timer_.expiry() + kInputPeriod);
  input_timer_.async_wait([this](error_code ec) {
    if (!ec) every_input_tick();
  });
}

void NetClient::every_second() {
  const double now = steady_seconds();
  const double span = now - second_started_;
  update_status([&](ConnectionStatus& s) {
    s.snapshots_per_s = static_cast<float>(snapshots_this_second_ / span);
    s.bytes_per_s = static_cast<float>(bytes_this_second_ / span);
  });
  snapshots_this_second_ = bytes_this_second_ = 0;
  second_started_ = now;
  if (connected_) send(protocol::encode_ping(static_cast<std::uint32_t>((now - ping_epoch_) * 1e6)));
  second_timer_.expires_at(second_timer_.expiry() + std::chrono::seconds(1));
  second_timer_.async_wait([this](error_code ec) {
    if (!ec) every_second();
  });
}

}  // namespace fishtank::viewer
