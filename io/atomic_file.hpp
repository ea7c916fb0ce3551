#pragma once
// Write a file so that readers never see it half-written: the content goes to a temporary file
// in the same directory (so that the final rename stays on one file system and is atomic under
// POSIX), which replaces the target only once it has been written, flushed and synced.
#include <filesystem>
#include <functional>
#include <string>
#include <ostream>

namespace geode::io {

// Calls `write` with a stream on a temporary file next to `path`, then renames it over `path`.
// If `write` throws or the stream fails, the temporary file is removed, `path` is left as it
// was, and the exception propagates (stream failures become geode::InvalidInput naming `path`).
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write);

// The same for libraries that write by file name (Exodus II, Gmsh): `write` gets the path of a
// fresh, empty temporary file next to `path` (ending in `suffix`, for writers that choose the
// format by extension) and must fill it; an empty file afterwards counts as a failed write.
void write_path_atomically(const std::filesystem::path& path, const std::string& suffix,
                           const std::function<void(const std::filesystem::path& temp)>& write);

}  // namespace geode::io
