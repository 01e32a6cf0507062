// Binary checkpoint streams: plain values and arrays of plain values with a length prefix, written in the machine's
// own byte order (a checkpoint resumes on the machine, or the same kind of machine, that wrote it), closed by a
// checksum (64-bit FNV-1a of every byte before it). A reader that meets the end of the file, a length longer than
// what is left of the file, or a checksum that does not match throws, naming what it was reading: a damaged
// checkpoint is refused, never resumed.
#pragma once
#include <algorithm>
#include <cstdint>
#include <istream>
#include <ostream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace demcal::kernel {

/// 64-bit FNV-1a, fed in pieces.
class Fnv1a64 {
 public:
  void add(const char* p, std::size_t n) {
    for (std::size_t k = 0; k < n; ++k) h_ = (h_ ^ std::uint8_t(p[k])) * 0x100000001b3ULL;
  }
  std::uint64_t value() const { return h_; }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ULL;
};

class StateWriter {
 public:
  explicit StateWriter(std::ostream& os) : os_(os) {}
  template <class T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T> || std::is_standard_layout_v<T>, "plain values only");
    bytes(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  // Eigen's fixed-size vectors and quaternions are contiguous doubles: written as their bytes.
  template <class T>
  void array(const std::vector<T>& a) {
    value(std::uint64_t(a.size()));
    if (!a.empty()) bytes(reinterpret_cast<const char*>(a.data()), a.size() * sizeof(T));
  }
  void text(const std::string& s) {
    value(std::uint64_t(s.size()));
    bytes(s.data(), s.size());
  }
  /// Writes the checksum of everything written so far (the end of a section).
  void checksum() {
    const std::uint64_t h = hash_.value();
    os_.write(reinterpret_cast<const char*>(&h), sizeof h);
  }
  bool ok() const { return bool(os_); }

 private:
  void bytes(const char* p, std::size_t n) {
    hash_.add(p, n);
    os_.write(p, std::streamsize(n));
  }
  std::ostream& os_;
  Fnv1a64 hash_;
};

class StateReader {
 public:
  StateReader(std::istream& is, std::string source) : is_(is), source_(std::move(source)) {
    // what is left of the stream, where it can tell (a file): no length may claim more
    const auto here = is_.tellg();
    if (here != std::streampos(-1) && is_.seekg(0, std::ios::end)) {
      const auto end = is_.tellg();
      if (end != std::streampos(-1) && end >= here) left_ = std::uint64_t(end - here);
    }
    is_.clear();
    is_.seekg(here);
  }
  template <class T>
  void value(T& v, const char* what) {
    if constexpr (std::is_same_v<T, bool>) {
      // a damaged byte must not become a bool that is neither true nor false (undefined behaviour)
      unsigned char b = 0;
      bytes(reinterpret_cast<char*>(&b), 1, what);
      if (b > 1) fail(what, "not a truth value (byte " + std::to_string(b) + ")");
      v = b != 0;
    } else {
      bytes(reinterpret_cast<char*>(&v), sizeof(T), what);
    }
  }
  template <class T>
  T value(const char* what) {
    T v{};
    value(v, what);
    return v;
  }
  template <class T>
  void array(std::vector<T>& a, const char* what) {
    const auto n = value<std::uint64_t>(what);
    if (n > (std::uint64_t(1) << 34) / sizeof(T)) fail(what, "implausible length " + std::to_string(n));
    if (n > left_ / sizeof(T)) fail(what, "the file ends early (" + std::to_string(n) + " values claimed)");
    a.resize(n);
    if (n) bytes(reinterpret_cast<char*>(a.data()), n * sizeof(T), what);
  }
  std::string text(const char* what) {
    const auto n = value<std::uint64_t>(what);
    if (n > (1u << 20) || n > left_) fail(what, "implausible length " + std::to_string(n));
    std::string s(n, '\0');
    bytes(s.data(), n, what);
    return s;
  }
  /// Reads the checksum a StateWriter wrote here and compares it with what was read since the start.
  void checksum() {
    const std::uint64_t expected = hash_.value();
    std::uint64_t stored = 0;
    is_.read(reinterpret_cast<char*>(&stored), sizeof stored);
    if (!is_) fail("checksum");
    left_ -= std::min<std::uint64_t>(left_, sizeof stored);
    if (stored != expected) fail("state", "checksum mismatch: the file is damaged");
  }
  [[noreturn]] void fail(const char* what, const std::string& why = "the file ends early") const {
    throw std::runtime_error(source_ + ": cannot read " + what + ": " + why);
  }

 private:
  void bytes(char* p, std::size_t n, const char* what) {
    if (n > left_) fail(what);
    is_.read(p, std::streamsize(n));
    if (!is_) fail(what);
    left_ -= n;
    hash_.add(p, n);
  }
  std::istream& is_;
  std::string source_;
  std::uint64_t left_ = UINT64_MAX;
  Fnv1a64 hash_;
};

}  // namespace demcal::kernel
