// Whole-file writes that a reader never sees half done.
#pragma once
#include <string>

namespace mrf {

// Writes `text` to `path` through `path`.tmp and a rename (atomic on POSIX
// file systems), so a reader, or a resumed sweep deciding whether a point is
// finished, never sees a partial file. Throws std::runtime_error on failure.
void write_file_atomic(const std::string& path, const std::string& text);

}  // namespace mrf
