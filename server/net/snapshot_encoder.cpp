#include "server/net/snapshot_encoder.h"

#include "protocol/quantize.h"

namespace fishtank::net {

void SnapshotEncoder::extend_kinds(const World& world, std::uint32_t scene_start) {
  const std::uint32_t n = world.ball_count();
  if (scene_start != scene_start_) {
    scene_start_ = scene_start;
    kinds_by_id_ = std::make_shared<std::vector<std::uint8_t>>();
  }
  if (kinds_by_id_->size() >= n) return;
  // Copy-on-grow: sessions may still hold the old table, so it is never modified.
  auto grown = std::make_shared<std::vector<std::uint8_t>>(*kinds_by_id_);
  const std::uint32_t known = static_cast<std::uint32_t>(grown->size());
  grown->resize(n);
  const std::uint32_t* ids = world.ids();
  const std::uint8_t* kinds = world.kinds();
  for (std::uint32_t i = 0; i < n; ++i)
    if (ids[i] >= known && ids[i] < n) (*grown)[ids[i]] = kinds[i];
  kinds_by_id_ = std::move(grown);
}

SharedSnapshot SnapshotEncoder::encode(const World& world, const protocol::SnapshotHeader& header) {
  auto published = std::make_shared<PublishedSnapshot>();
  const std::uint32_t n = world.ball_count();
  const TankBounds& tank = header.tank;
  published->header = header;
  published->ball_count = n;
  published->quantised.resize(3 * std::size_t{n});
  const Float4* pos = world.positions();
  const std::uint32_t* ids = world.ids();
  for (std::uint32_t i = 0; i < n; ++i) {
    if (ids[i] >= n) continue;  // ids are dense (0 .. n-1); this only guards the write
    protocol::quantize_position({pos[i].x, pos[i].y, pos[i].z}, tank, &published->quantised[3 * std::size_t{ids[i]}]);
  }

  const std::size_t players = world.player_count();
  published->player_ids.assign(world.player_ids().begin(), world.player_ids().end());
  published->player_positions.resize(players);
  for (std::size_t p = 0; p < players; ++p) {
    const Float4& q = world.player_positions()[p];
    published->player_positions[p] = {q.x, q.y, q.z};
  }

  extend_kinds(world, header.scene_start);
  published->kinds_by_id = kinds_by_id_;
  published->scene_start = header.scene_start;
  return published;
}

}  // namespace fishtank::net
