#pragma once
// From a pair of snapshots to the spheres of one frame: positions blended
// between the two, sizes and colours from the ball kinds, players in white.

#include <vector>

#include "viewer/net/snapshot_buffer.h"
#include "viewer/render/instance.h"

namespace fishtank::viewer {

// Fills `out` with the balls (id order) followed by the players. Returns the
// index in `out` of the viewer's own player, or -1 when it has none.
int interpolate(const RenderPair& pair, const ServerInfo& info, std::vector<SphereInstance>& out);

}  // namespace fishtank::viewer
