#include <geode/io/netcdf_screen.hpp>

#include <cstdint>
#include <limits>
#include <string_view>
#include <vector>

#include <geode/io/mapped_file.hpp>
#include <geode/primal/errors.hpp>

namespace geode::io {

namespace {

constexpr std::string_view kHdf5Signature("\x89HDF\r\n\x1a\n", 8);

// The classic header as the netCDF format specification gives it ("The NetCDF Classic Format
// Specification", CDF-1, CDF-2 and CDF-5): magic numrecs dim_list gatt_list var_list.
class ClassicHeader {
 public:
  ClassicHeader(std::string_view bytes, std::string source)
      : b_(bytes), source_(std::move(source)), version_(static_cast<int>(bytes[3])) {}

  void check() {
    pos_ = 4;
    const std::uint64_t numrecs = version_ == 5 ? be(8) : be(4);
    const bool streaming =
        numrecs == (version_ == 5 ? std::numeric_limits<std::uint64_t>::max() : 0xFFFFFFFFu);
    dimensions();
    attributes("a global attribute");
    variables();
    const std::uint64_t header_end = pos_;
    const std::uint64_t size = b_.size();
    for (const Variable& v : variables_)
      if (v.begin < header_end)
        fail("variable " + v.name + ": its data starts at byte " + std::to_string(v.begin) +
             ", inside the header");
    if (record_bytes_ > 0 && !streaming && numrecs > 0) {
      if (record_begin_ > size || numrecs > (size - record_begin_) / record_bytes_)
        fail("its " + std::to_string(numrecs) + " records of " + std::to_string(record_bytes_) +
             " bytes from byte " + std::to_string(record_begin_) + " go past the end");
    }
  }

 private:
  struct Variable {
    std::string name;
    std::uint64_t begin = 0;
  };

  [[noreturn]] void fail(const std::string& why) const {
    throw InvalidInput(source_ + ": not a consistent netCDF classic file (" + why +
                       "; the file has " + std::to_string(b_.size()) +
                       " bytes): corrupt or truncated?");
  }
  std::uint64_t left() const { return b_.size() - pos_; }
  std::uint64_t be(std::size_t n) {
    if (left() < n) fail("the header ends early, at byte " + std::to_string(pos_));
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < n; ++i) v = v << 8 | static_cast<unsigned char>(b_[pos_ + i]);
    pos_ += n;
    return v;
  }
  // NON_NEG: 4 bytes in CDF-1 and CDF-2, 8 in CDF-5 (element counts, lengths, ids, sizes).
  std::uint64_t non_neg() {
    const std::uint64_t v = version_ == 5 ? be(8) : be(4);
    if (version_ != 5 && v > 0x7FFFFFFFu) fail("a negative count at byte " + std::to_string(pos_));
    return v;
  }
  void skip(std::uint64_t n, const std::string& what) {
    const std::uint64_t padded = n + (4 - n % 4) % 4;
    if (n > left() || padded > left())
      fail(what + " of " + std::to_string(n) + " bytes at byte " + std::to_string(pos_) +
           " goes past the end");
    pos_ += padded;
  }
  std::string name(const char* what) {
    const std::uint64_t n = non_neg();
    if (n == 0 || n > 256) fail(std::string(what) + " name of " + std::to_string(n) + " bytes");
    const std::size_t at = pos_;
    skip(n, std::string(what) + " name");
    return std::string(b_.substr(at, n));
  }
  // The number of entries of a list tagged `tag` (0 for ABSENT), each at least `least` bytes.
  std::uint64_t list(std::uint64_t tag, std::uint64_t least, const char* what) {
    const std::uint64_t t = be(4), n = non_neg();
    if (t == 0 && n == 0) return 0;
    if (t != tag) fail(std::string("no ") + what + " list tag at byte " + std::to_string(pos_ - 8));
    if (n > left() / least)
      fail(std::to_string(n) + " " + what + "s announced, more than the header can hold");
    return n;
  }
  std::uint64_t type_size(std::uint64_t type) {
    switch (type) {
      case 1:  // NC_BYTE
      case 2:  // NC_CHAR
        return 1;
      case 3:  // NC_SHORT
        return 2;
      case 4:  // NC_INT
      case 5:  // NC_FLOAT
        return 4;
      case 6:  // NC_DOUBLE
        return 8;
      default:
        break;
    }
    if (version_ == 5) {
      if (type == 7) return 1;                 // NC_UBYTE
      if (type == 8) return 2;                 // NC_USHORT
      if (type == 9) return 4;                 // NC_UINT
      if (type == 10 || type == 11) return 8;  // NC_INT64, NC_UINT64
    }
    fail("unknown data type " + std::to_string(type) + " at byte " + std::to_string(pos_ - 4));
  }
  void dimensions() {
    const std::uint64_t n = list(0x0A, 8, "dimension");
    for (std::uint64_t d = 0; d < n; ++d) {
      const std::string dim = name("a dimension");
      const std::uint64_t length = non_neg();
      if (length == 0) {
        if (record_dim_ >= 0) fail("two unlimited dimensions");
        record_dim_ = static_cast<std::int64_t>(d);
      }
      lengths_.push_back(length);
    }
  }
  void attributes(const std::string& what) {
    const std::uint64_t n = list(0x0C, 12, "attribute");
    for (std::uint64_t a = 0; a < n; ++a) {
      const std::string attribute = name("an attribute");
      const std::uint64_t size = type_size(be(4));
      const std::uint64_t count = non_neg();
      if (count > left() / size)
        fail(what + " '" + attribute + "' of " + std::to_string(count) +
             " values goes past the end");
      skip(count * size, what + " '" + attribute + "'");
    }
  }
  void variables() {
    const std::uint64_t size = b_.size();
    const std::uint64_t n = list(0x0B, 16, "variable");
    for (std::uint64_t i = 0; i < n; ++i) {
      Variable v;
      v.name = "'" + name("a variable") + "'";
      const std::uint64_t rank = non_neg();
      if (rank > left() / 4) fail("variable " + v.name + " of rank " + std::to_string(rank));
      std::uint64_t elements = 1;
      bool record = false;
      for (std::uint64_t r = 0; r < rank; ++r) {
        const std::uint64_t dim = non_neg();
        if (dim >= lengths_.size())
          fail("variable " + v.name + " on dimension " + std::to_string(dim) + " of " +
               std::to_string(lengths_.size()));
        if (static_cast<std::int64_t>(dim) == record_dim_) {
          if (r != 0) fail("variable " + v.name + " has its unlimited dimension not first");
          record = true;
          continue;
        }
        // Bounded by the file's size as it goes: no product overflows.
        if (lengths_[dim] > 0 && elements > size / lengths_[dim])
          fail("variable " + v.name + " is larger than the file");
        elements *= lengths_[dim];
      }
      attributes("attribute of variable " + v.name);
      const std::uint64_t bytes_each = type_size(be(4));
      (void)non_neg();  // vsize: recomputed below, never trusted
      v.begin = version_ == 1 ? be(4) : be(8);
      if (elements > size / bytes_each) fail("variable " + v.name + " is larger than the file");
      const std::uint64_t bytes = elements * bytes_each;
      if (record) {
        if (v.begin > size)
          fail("variable " + v.name + ": its records start at byte " + std::to_string(v.begin) +
               ", past the end");
        if (record_bytes_ == 0 || v.begin < record_begin_) record_begin_ = v.begin;
        record_bytes_ += bytes;
        if (record_bytes_ > size) fail("one record is larger than the file");
      } else if (v.begin > size || bytes > size - v.begin) {
        fail("variable " + v.name + ": its " + std::to_string(bytes) + " bytes of data at byte " +
             std::to_string(v.begin) + " go past the end");
      }
      variables_.push_back(std::move(v));
    }
  }

  std::string_view b_;
  std::string source_;
  int version_;
  std::size_t pos_ = 0;
  std::vector<std::uint64_t> lengths_;
  std::int64_t record_dim_ = -1;
  std::vector<Variable> variables_;
  std::uint64_t record_begin_ = 0, record_bytes_ = 0;
};

std::uint64_t le(std::string_view b, std::size_t at, std::size_t n) {
  std::uint64_t v = 0;
  for (std::size_t i = n; i-- > 0;) v = v << 8 | static_cast<unsigned char>(b[at + i]);
  return v;
}

// The HDF5 superblock (HDF5 File Format Specification, "Superblock", versions 0 to 3) at
// `at`: sizes of offsets and lengths a reader can use, the end-of-file address inside the file
// and the root group before it (addresses are relative to the superblock's position).
void check_hdf5_superblock(std::string_view b, std::size_t at, const std::string& source) {
  const auto fail = [&](const std::string& why) {
    throw InvalidInput(source + ": not a consistent netCDF-4 (HDF5) file (" + why +
                       "; the file has " + std::to_string(b.size()) +
                       " bytes): corrupt or truncated?");
  };
  if (b.size() < at + 16) fail("the superblock is cut short");
  const int version = static_cast<unsigned char>(b[at + 8]);
  if (version > 3) fail("superblock version " + std::to_string(version));
  const std::size_t offsets = static_cast<unsigned char>(b[at + (version < 2 ? 13 : 9)]);
  const std::size_t lengths = static_cast<unsigned char>(b[at + (version < 2 ? 14 : 10)]);
  for (std::size_t s : {offsets, lengths})
    if (s != 2 && s != 4 && s != 8) fail("addresses of " + std::to_string(s) + " bytes");
  // v0: 24 bytes before the base address, v1: 28 (indexed storage K); v2/3: 12.
  const std::size_t base_at = at + (version == 0 ? 24 : version == 1 ? 28 : 12);
  const std::size_t eof_at = base_at + 2 * offsets;  // after base, free-space / extension
  if (b.size() < eof_at + 2 * offsets) fail("the superblock is cut short");
  // libhdf5 takes the superblock's position as the base whatever the field says.
  const std::uint64_t eof = le(b, eof_at, offsets);
  if (eof > b.size() - at)
    fail("its superblock says " + std::to_string(at + eof) + " bytes: the file is truncated");
  // The root group: its object header (v2/3), or its symbol table entry's (v0/1).
  const std::size_t root_at = version < 2 ? eof_at + 2 * offsets + offsets : eof_at + offsets;
  if (b.size() < root_at + offsets) fail("the superblock is cut short");
  const std::uint64_t root = le(b, root_at, offsets);
  if (root >= eof) fail("the root group at " + std::to_string(root) + " is past the end");
}

}  // namespace

NetcdfKind screen_netcdf(const std::filesystem::path& path, const std::string& source) {
  const MappedFile file(path);
  const std::string_view b = file.bytes();
  if (b.size() >= 4 && b.substr(0, 3) == "CDF" && (b[3] == 1 || b[3] == 2 || b[3] == 5)) {
    ClassicHeader(b, source).check();
    return NetcdfKind::kClassic;
  }
  // HDF5 looks for its signature at 0 and at each power of two from 512 (a user block).
  for (std::size_t at = 0; at + kHdf5Signature.size() <= b.size() && at <= 2048;
       at = at == 0 ? 512 : 2 * at)
    if (b.substr(at, kHdf5Signature.size()) == kHdf5Signature) {
      check_hdf5_superblock(b, at, source);
      return NetcdfKind::kHdf5;
    }
  throw InvalidInput(source + ": not in Exodus II format (no netCDF or HDF5 signature)");
}

}  // namespace geode::io
