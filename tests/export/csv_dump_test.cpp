// The final-state CSV (--dump): one row per ball in id order with the world's
// own values, and a refusal, not a silent short file, where the disk is full.

#include "server/export/csv_dump.h"

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "server/physics/world_measures.h"

using namespace fishtank;

TEST_CASE("the CSV dump has a row per ball, in id order, with its position, velocity, diameter and mass",
          "[export][dump]") {
  World world(PhysicsParams{}, kSseKernels, 1, 5);
  world.add_balls(60);
  for (int s = 0; s < 500; ++s) world.step();  // the step sorts balls by cell, so ids and indices part
  const auto path = std::filesystem::temp_directory_path() / "fishtank-csv-dump-test.csv";
  REQUIRE(write_csv_dump(world, path.string()).empty());

  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  CHECK(line == "x,y,z,vx,vy,vz,diameter,mass");
  const std::vector<std::uint32_t> by_id = indices_by_id(world);
  std::uint32_t id = 0;
  for (; std::getline(in, line); ++id) {
    REQUIRE(id < by_id.size());
    std::vector<float> values;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) values.push_back(std::stof(cell));
    REQUIRE(values.size() == 8);
    const Float4& p = world.positions()[by_id[id]];
    const Float4& v = world.velocities()[by_id[id]];
    // %.7g keeps 7 significant digits.
    const float expected[8] = {p.x, p.y, p.z, v.x, v.y, v.z, 2.0f * p.w, v.w};
    for (int column = 0; column < 8; ++column)
      CHECK(values[column] == Approx(expected[column]).epsilon(1e-6).margin(1e-6));
  }
  CHECK(id == world.ball_count());
  std::filesystem::remove(path);
}

TEST_CASE("a CSV dump that cannot all reach the disk says so", "[export][dump]") {
  if (!std::filesystem::exists("/dev/full")) {
    WARN("SKIPPED: no /dev/full here (every write to it fails, as on a full disk)");
    return;
  }
  World world(PhysicsParams{}, kSseKernels, 1, 5);
  world.add_balls(3000);  // far more than the C library buffers: writes fail while rows are printed
  CHECK(write_csv_dump(world, "/dev/full") == "error while writing /dev/full");
}
