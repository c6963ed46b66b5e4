// The label L of a label selection (paper §3.1: the 1-voxels are f = L), held exactly. Segment
// ids of connectomics volumes are uint64 values far above 2^53, where doubles skip integers
// (2^53 + 1 rounds to 2^53), so a label is a sign and a 64-bit magnitude: every value of the
// eight integer scalar types (ScalarType.h), int64's and uint64's ranges together.
// Part of the public API, so it depends on nothing but the standard library.
#pragma once

#include <charconv>
#include <cmath>
#include <compare>
#include <cstdint>
#include <limits>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <type_traits>

namespace surftrack {

class LabelValue {
 public:
  constexpr LabelValue() = default;
  /// Any integer (not bool), exactly.
  template <class I, std::enable_if_t<std::is_integral_v<I> && !std::is_same_v<I, bool>, int> = 0>
  constexpr LabelValue(I v) noexcept  // NOLINT(google-explicit-constructor): labels are integers
      : negative_(v < 0), magnitude_(v < 0 ? std::uint64_t(0) - std::uint64_t(v) : std::uint64_t(v)) {}

  /// The label equal to `v`, or none when v is not an integer in [-2^63, 2^64) (a fraction,
  /// NaN, an infinity, or beyond 64 bits).
  static std::optional<LabelValue> fromDouble(double v) {
    if (!(v == std::floor(v)) || !(v >= -0x1p63) || !(v < 0x1p64)) return std::nullopt;
    LabelValue L;
    L.negative_ = v < 0;
    L.magnitude_ = std::uint64_t(std::fabs(v));  // exact: an integer below 2^64
    return L;
  }

  /// Parses an optional sign and decimal digits exactly ("-12", "18446744073709551615"); none
  /// for any other text or a value out of [-2^63, 2^64).
  static std::optional<LabelValue> parse(std::string_view text) {
    bool negative = false;
    if (!text.empty() && (text[0] == '-' || text[0] == '+')) {
      negative = text[0] == '-';
      text.remove_prefix(1);
    }
    if (text.empty() || text[0] < '0' || text[0] > '9') return std::nullopt;
    std::uint64_t m = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), m);
    if (ec != std::errc{} || end != text.data() + text.size()) return std::nullopt;
    if (negative && m > (std::uint64_t(1) << 63)) return std::nullopt;
    LabelValue L;
    L.negative_ = negative && m != 0;
    L.magnitude_ = m;
    return L;
  }

  constexpr bool negative() const { return negative_; }
  /// |L|.
  constexpr std::uint64_t magnitude() const { return magnitude_; }

  /// Whether L is a value of the scalar type T (integers: in range; floats: exactly).
  template <class T>
  bool fits() const {
    if constexpr (std::is_integral_v<T>) {
      if constexpr (std::is_signed_v<T>)
        return negative_ ? magnitude_ <= std::uint64_t(std::numeric_limits<T>::max()) + 1
                         : magnitude_ <= std::uint64_t(std::numeric_limits<T>::max());
      else
        return !negative_ && magnitude_ <= std::uint64_t(std::numeric_limits<T>::max());
    } else {
      const T v = T(toDouble());
      const std::optional<LabelValue> back = fromDouble(double(v));
      return back && *back == *this;
    }
  }
  /// L as a T (fits<T>() checked beforehand).
  template <class T>
  constexpr T as() const {
    if constexpr (std::is_integral_v<T>)
      return negative_ ? T(-std::int64_t(magnitude_ - 1) - 1) : T(magnitude_);
    else
      return T(toDouble());
  }
  /// The nearest double: exact up to 2^53.
  constexpr double toDouble() const { return negative_ ? -double(magnitude_) : double(magnitude_); }

  /// Decimal digits, exactly.
  std::string text() const {
    std::string digits = std::to_string(magnitude_);
    if (negative_) digits.insert(digits.begin(), '-');
    return digits;
  }

  friend constexpr bool operator==(const LabelValue&, const LabelValue&) = default;
  friend constexpr std::strong_ordering operator<=>(const LabelValue& a, const LabelValue& b) {
    if (a.negative_ != b.negative_) return a.negative_ ? std::strong_ordering::less : std::strong_ordering::greater;
    return a.negative_ ? b.magnitude_ <=> a.magnitude_ : a.magnitude_ <=> b.magnitude_;
  }
  friend std::ostream& operator<<(std::ostream& out, const LabelValue& L) { return out << L.text(); }

 private:
  bool negative_ = false;  ///< never with a zero magnitude: one zero
  std::uint64_t magnitude_ = 0;
};

}  // namespace surftrack
