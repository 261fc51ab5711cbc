#pragma once
// Where a new player sphere appears (SPEC 1.4: in the centre of the tank): at
// the point with the most room among a few near the centre, so that players who
// join together start apart and, where the tank leaves room, outside every ball.

#include <cstddef>

#include "common/float4.h"
#include "common/tank.h"

namespace fishtank {

// players and balls hold x, y, z and the radius in w. With no player and no
// ball the answer is the tank's centre. It overlaps no player while any point
// of the candidate lattice inside the tank is free of them.
Vec3 choose_player_spawn(const TankBounds& tank, const Float4* players, std::size_t player_count, const Float4* balls,
                         std::size_t ball_count);

}  // namespace fishtank
