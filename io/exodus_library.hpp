#pragma once
// libexodusII helpers shared by the Exodus reader (exodus_read.cpp) and writer (exodus.cpp):
// an owned file id, error causes in words, name buffers. Internal to io/: includes exodusII.h.
#include <exodusII.h>
#include <netcdf.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <string>
#include <vector>

#include <geode/io/names.hpp>
#include <geode/primal/errors.hpp>

namespace geode::io::exodus_library {

// Longer names than Exodus's default 32 characters.
constexpr int kNameLength = 80;

// An element block property: the id of the model block an Exodus block belongs to. An Exodus
// block holds one element type, so the writer splits a model block of several kinds (Gmsh's
// tets and pyramids in one volume) and gives each part this property; the reader joins the
// parts again.
constexpr const char* kBlockProperty = "GEODE_BLOCK";

// Owns an open Exodus file id.
class ExodusFile {
 public:
  explicit ExodusFile(int id) : id_(id) {}
  ~ExodusFile() {
    if (id_ >= 0) ex_close(id_);
  }
  ExodusFile(const ExodusFile&) = delete;
  ExodusFile& operator=(const ExodusFile&) = delete;
  int id() const { return id_; }
  int close() {
    const int status = ex_close(id_);
    id_ = -1;
    return status;
  }

 private:
  int id_;
};

// The cause libexodusII recorded for its last error: a system error (ENOSPC on a full disk)
// or a netCDF / Exodus one, in words.
inline std::string error_cause(int err) {
  if (err > 0)
    return std::string(std::strerror(err)) +
           (err == ENOSPC || err == EDQUOT ? " (the disk is full)" : "");
  if (err < 0) return nc_strerror(err);
  return "Exodus error";
}
inline std::string exodus_cause() {
  const char* msg = nullptr;
  const char* func = nullptr;
  int err = 0;
  ex_get_err(&msg, &func, &err);
  return error_cause(err);
}

// `where` names the file the user gave (never the temporary one a write goes through).
inline void check(int status, const std::string& where, const std::string& what) {
  if (status < 0) throw InvalidInput(where + ": " + what + " failed: " + exodus_cause());
}
// A netCDF call's status (NC_NOERR, an errno, or a netCDF error).
inline void check_netcdf(int status, const std::string& where, const std::string& what) {
  if (status != NC_NOERR)
    throw InvalidInput(where + ": " + what + " failed: " + error_cause(status));
}

// Names as Exodus wants them: an array of char* to buffers of kNameLength + 1.
struct NameBuffers {
  std::vector<std::vector<char>> storage;
  std::vector<char*> pointers;
  explicit NameBuffers(std::size_t n) : storage(n, std::vector<char>(kNameLength + 1, '\0')) {
    for (auto& s : storage) pointers.push_back(s.data());
  }
  void set(std::size_t i, const std::string& name) {
    const std::string safe = sanitize_name(name);
    std::size_t n = std::min<std::size_t>(safe.size(), kNameLength);
    while (n > 0 && n < safe.size() && (static_cast<unsigned char>(safe[n]) & 0xC0) == 0x80)
      --n;  // whole characters
    std::copy_n(safe.begin(), n, storage[i].begin());
  }
  std::string get(std::size_t i) const {
    return std::string(storage[i].data(), strnlen(storage[i].data(), kNameLength));
  }
};

}  // namespace geode::io::exodus_library
