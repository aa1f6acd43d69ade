// The version of mrf and the git revision the binary was built from
// (`git describe --always --dirty`, "unknown" outside a git checkout), for
// `mrf --version` and summary.json.
#pragma once

namespace mrf {

inline const char* version() { return MRF_VERSION; }
const char* git_revision();

}  // namespace mrf
