// The JSON metadata of chunked stores (zarr's .zarray and .zattrs, N5's attributes.json) read
// with nlohmann-json, and the checked access the readers share: every malformed field is a
// ReadError of one line naming the file and the field, never an exception of the JSON library.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace surftrack::io::detail {

/// The JSON document in file `path`, or nothing if there is no such file. Throws ReadError
/// "cannot read '<path>': ..." for a file that cannot be read or is not JSON.
std::optional<nlohmann::json> readJsonFile(const std::string& path);

/// The JSON text of `value`, shortened to about 60 characters, for messages.
std::string jsonText(const nlohmann::json& value);

/// Field `key` of `object`: a list of integers, each at least `minimum`. Throws ReadError
/// "<context>: '<key>' must be a list of integers >= <minimum>, not ...".
std::vector<std::int64_t> integerList(const nlohmann::json& object, const char* key, std::int64_t minimum,
                                      const std::string& context);

/// Field `key` of `object`: a list of finite numbers.
std::vector<double> numberList(const nlohmann::json& object, const char* key, const std::string& context);

}  // namespace surftrack::io::detail
