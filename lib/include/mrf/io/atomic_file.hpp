// Whole-file writes that a reader never sees half done.
#pragma once
#include <string>

namespace mrf {

// Writes `text` to `path` through `path`.tmp and a rename (atomic on POSIX
// file systems), so a reader, or a resumed sweep deciding whether a point is
// finished, never sees a partial file; the file is synced to the disk before
// the rename and its folder after it, so a crash just after the write does
// not leave the name on an empty file. Throws OutputError on failure
// (including an error that shows only when the file is closed).
void write_file_atomic(const std::string& path, const std::string& text);

}  // namespace mrf
