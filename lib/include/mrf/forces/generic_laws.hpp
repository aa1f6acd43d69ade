// The generic pair laws of laws-inl.h in namespace mrf (the scalar ones;
// DipoleX::eval and hertz_law call them with T = double).
#pragma once

namespace mrf {
#include "mrf/forces/laws-inl.h"
}  // namespace mrf
