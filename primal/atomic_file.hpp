#pragma once
// Write a file so that readers never see it half-written: the content goes to a temporary file
// in the same directory (so that the final rename stays on one file system and is atomic under
// POSIX), which replaces the target only once it has been written, flushed and synced.
#include <filesystem>
#include <functional>
#include <ostream>

namespace geode::primal {

// Calls `write` with a stream on a temporary file next to `path`, then renames it over `path`.
// If `write` throws or the stream fails, the temporary file is removed, `path` is left as it
// was, and the exception propagates (stream failures become geode::InvalidInput naming `path`).
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write);

}  // namespace geode::primal
