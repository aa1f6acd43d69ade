// Pure text helpers of the scene loader's messages (io/toml_scene.cpp):
// did-you-mean distances and naming the key of a line a TOML parser refused.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>

namespace mrf {

// Levenshtein distance (insertions, deletions, substitutions).
std::size_t edit_distance(std::string_view a, std::string_view b);

// "[name]" or "[[name]]" -> name.
std::string toml_header_name(std::string_view line);

// The key ("section.name") and value as written on 1-based line `line` of
// TOML `text`, when that line is "name = value"; else {the line, ""}, or
// {"(end of file)", ""} past the end.
std::pair<std::string, std::string> toml_key_on_line(std::string_view text, std::uint32_t line);

}  // namespace mrf
