// The contact law's own facts (contact_law.h), checked on the scalar law:
// a contact at rest pushes with k x alone, and the SIMD twin's fast path,
// k x - now v_n - before v_before, is the same law where a contact lasts the
// whole window now and lasted it a step before.

#include "server/physics/contact_law.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "server/physics/params.h"

using namespace fishtank;

namespace {

ContactModel model_with(float restitution) {
  PhysicsParams params;
  params.restitution = restitution;
  return make_contact_model(params);
}

}  // namespace

TEST_CASE("a contact at rest pushes with k x: the spring and the other forces cancel in the dashpot's rate",
          "[physics][law]") {
  for (float e : {0.05f, 0.6f, 1.0f}) {
    const ContactModel m = model_with(e);
    const float inv_m_sum = 2.0f, c = contact_damping(m, inv_m_sum);
    for (float overlap : {1e-4f, 3e-3f, 0.05f}) {
      INFO("e = " << e << ", overlap " << overlap);
      CHECK(normal_force(m, overlap, 0.0f, c, inv_m_sum, 0.0f) == Approx(m.k * overlap).epsilon(1e-6));
    }
  }
}

TEST_CASE("where a contact lasts the whole window now and a step before, the law is k x - now v_n - before v_before",
          "[physics][law]") {
  std::mt19937 random(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  int checked = 0;
  for (float e : {0.05f, 0.3f, 0.6f, 0.9f}) {
    const ContactModel m = model_with(e);
    for (float inv_m_sum : {2.0f, 1.0f, 0.25f}) {
      const float c = contact_damping(m, inv_m_sum);
      const WholeWindowDamping d = whole_window_damping(m, c, inv_m_sum);
      for (int trial = 0; trial < 200; ++trial) {
        const float overlap = 0.1f * unit(random), v_n = 4.0f * unit(random) - 2.0f;
        const float v_before = v_n + (unit(random) - 0.5f);
        const float lead = std::fabs(v_n) * m.half_dt, then = overlap + v_n * m.dt;
        if (overlap < lead || then < std::fabs(v_before) * m.half_dt) continue;  // not whole, now or then
        const float law = normal_force(m, overlap, v_n, c, inv_m_sum, v_before);
        INFO("e = " << e << ", 1/m_eff " << inv_m_sum << ", x " << overlap << ", v_n " << v_n << ", before "
                    << v_before);
        CHECK(m.k * overlap - d.now * v_n - d.before * v_before == Approx(law).epsilon(1e-5).margin(1e-3));
        ++checked;
      }
    }
  }
  CHECK(checked > 1000);
}
