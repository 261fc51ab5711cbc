#include "common/fp_env.h"

#include <pmmintrin.h>
#include <xmmintrin.h>

namespace fishtank {

void enable_flush_denormals_to_zero() {
  _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
  _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

}  // namespace fishtank
