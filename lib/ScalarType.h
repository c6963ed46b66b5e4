// The scalar types a volume's voxels may have, as the front door (docs/api.md) names them.
// Part of the public API, so it depends on nothing but the standard library.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>

namespace surftrack {

enum class ScalarType { UInt8, Int8, UInt16, Int16, UInt32, Int32, UInt64, Int64, Float32, Float64 };

/// The ScalarType of a C++ type; only the ten types above have one.
template <class T>
constexpr ScalarType scalarTypeOf() {
  if constexpr (std::is_same_v<T, std::uint8_t>) return ScalarType::UInt8;
  else if constexpr (std::is_same_v<T, std::int8_t>) return ScalarType::Int8;
  else if constexpr (std::is_same_v<T, std::uint16_t>) return ScalarType::UInt16;
  else if constexpr (std::is_same_v<T, std::int16_t>) return ScalarType::Int16;
  else if constexpr (std::is_same_v<T, std::uint32_t>) return ScalarType::UInt32;
  else if constexpr (std::is_same_v<T, std::int32_t>) return ScalarType::Int32;
  else if constexpr (std::is_same_v<T, std::uint64_t>) return ScalarType::UInt64;
  else if constexpr (std::is_same_v<T, std::int64_t>) return ScalarType::Int64;
  else if constexpr (std::is_same_v<T, float>) return ScalarType::Float32;
  else {
    static_assert(std::is_same_v<T, double>, "unsupported voxel type");
    return ScalarType::Float64;
  }
}

/// Calls f(T{}) with the C++ type of `type`: the one switch over the ten types.
template <class F>
decltype(auto) visitScalarType(ScalarType type, F&& f) {
  switch (type) {
    case ScalarType::UInt8: return f(std::uint8_t{});
    case ScalarType::Int8: return f(std::int8_t{});
    case ScalarType::UInt16: return f(std::uint16_t{});
    case ScalarType::Int16: return f(std::int16_t{});
    case ScalarType::UInt32: return f(std::uint32_t{});
    case ScalarType::Int32: return f(std::int32_t{});
    case ScalarType::UInt64: return f(std::uint64_t{});
    case ScalarType::Int64: return f(std::int64_t{});
    case ScalarType::Float32: return f(float{});
    case ScalarType::Float64: break;
  }
  return f(double{});
}

/// "uint8", "int8", "uint16", "int16", "uint32", "int32", "uint64", "int64", "float", "double".
inline std::string toString(ScalarType type) {
  static constexpr const char* kNames[] = {"uint8", "int8",  "uint16", "int16", "uint32",
                                           "int32", "uint64", "int64", "float", "double"};
  return kNames[int(type)];
}

inline std::size_t sizeOf(ScalarType type) {
  return visitScalarType(type, [](auto v) { return sizeof(v); });
}

inline bool isInteger(ScalarType type) {
  return type != ScalarType::Float32 && type != ScalarType::Float64;
}

/// Parses the names of toString and the aliases u8 i8 u16 i16 u32 i32 u64 i64 f32 f64, uchar,
/// char, ushort, short, uint, int, float32, float64; throws std::invalid_argument otherwise.
inline ScalarType parseScalarType(std::string_view text) {
  struct Alias {
    std::string_view name;
    ScalarType type;
  };
  static constexpr Alias kAliases[] = {
      {"u8", ScalarType::UInt8},      {"uchar", ScalarType::UInt8},    {"i8", ScalarType::Int8},
      {"char", ScalarType::Int8},     {"u16", ScalarType::UInt16},     {"ushort", ScalarType::UInt16},
      {"i16", ScalarType::Int16},     {"short", ScalarType::Int16},    {"u32", ScalarType::UInt32},
      {"uint", ScalarType::UInt32},   {"i32", ScalarType::Int32},      {"int", ScalarType::Int32},
      {"u64", ScalarType::UInt64},    {"i64", ScalarType::Int64},      {"f32", ScalarType::Float32},
      {"float32", ScalarType::Float32}, {"f64", ScalarType::Float64},  {"float64", ScalarType::Float64}};
  for (int t = 0; t < 10; ++t)
    if (text == toString(ScalarType(t))) return ScalarType(t);
  for (const Alias& a : kAliases)
    if (text == a.name) return a.type;
  throw std::invalid_argument("unsupported voxel type '" + std::string(text) +
                              "': expected uint8, int8, uint16, int16, uint32, int32, uint64, "
                              "int64, float or double");
}

}  // namespace surftrack
