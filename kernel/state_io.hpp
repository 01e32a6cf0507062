// Binary checkpoint streams: plain values and arrays of plain values with a length prefix, written in the machine's
// own byte order (a checkpoint resumes on the machine, or the same kind of machine, that wrote it). A reader that
// meets the end of the file or an implausible length throws, naming what it was reading.
#pragma once
#include <cstdint>
#include <istream>
#include <ostream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace demcal::kernel {

class StateWriter {
 public:
  explicit StateWriter(std::ostream& os) : os_(os) {}
  template <class T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T> || std::is_standard_layout_v<T>, "plain values only");
    os_.write(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  // Eigen's fixed-size vectors and quaternions are contiguous doubles: written as their bytes.
  template <class T>
  void array(const std::vector<T>& a) {
    value(std::uint64_t(a.size()));
    if (!a.empty()) os_.write(reinterpret_cast<const char*>(a.data()), std::streamsize(a.size() * sizeof(T)));
  }
  void text(const std::string& s) {
    value(std::uint64_t(s.size()));
    os_.write(s.data(), std::streamsize(s.size()));
  }
  bool ok() const { return bool(os_); }

 private:
  std::ostream& os_;
};

class StateReader {
 public:
  StateReader(std::istream& is, std::string source) : is_(is), source_(std::move(source)) {}
  template <class T>
  void value(T& v, const char* what) {
    is_.read(reinterpret_cast<char*>(&v), sizeof(T));
    if (!is_) fail(what);
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
    a.resize(n);
    if (n) is_.read(reinterpret_cast<char*>(a.data()), std::streamsize(n * sizeof(T)));
    if (!is_) fail(what);
  }
  std::string text(const char* what) {
    const auto n = value<std::uint64_t>(what);
    if (n > (1u << 20)) fail(what, "implausible length " + std::to_string(n));
    std::string s(n, '\0');
    is_.read(s.data(), std::streamsize(n));
    if (!is_) fail(what);
    return s;
  }
  [[noreturn]] void fail(const char* what, const std::string& why = "the file ends early") const {
    throw std::runtime_error(source_ + ": cannot read " + what + ": " + why);
  }

 private:
  std::istream& is_;
  std::string source_;
};

}  // namespace demcal::kernel
