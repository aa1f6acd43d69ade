// Scene files: TOML text -> validated SceneConfig (SI units), remembering where
// each value came from so that later checks (e.g. the time-step limit in the
// model builder) can name the file line. The format, every key, its unit,
// default and constraint are documented in docs/scene-format.md.
//
// Every failure is an mrf::InputError naming the key ("section.key"), the value
// as written and its location: "FILE:LINE" for the file, "--set section.key=value"
// for an override, or the file alone for a missing key.
#pragma once
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "mrf/scene/config.hpp"

namespace mrf {

struct LoadedScene {
  SceneConfig config;
  // "section.key" -> "FILE:LINE" or "--set section.key=value", for every key given.
  std::map<std::string, std::string> where;
  std::string source;  // the file path (or the name given to parse_scene)

  // Location of a key: where[key], or `source` for a key left at its default.
  std::string locate(const std::string& key) const;
};

// Read and parse a scene file, then apply the overrides as parse_scene does.
LoadedScene load_scene(const std::string& path, const std::vector<std::string>& overrides = {});

// Parse scene text; `source_name` is used in locations. Each override is
// "section.key=value" where value is TOML syntax (0.1, "2.5 um", true); a value
// that is not valid TOML (a bare word such as overdamped, or 2.5 um unquoted) is
// taken as a string. An override of drive.mason replaces a drive.shear_rate given
// in the file and vice versa, unless drive.vary = "magnetization" (then both
// are needed and the magnetisation follows). Validates and fills the derived
// mason / shear_rate / magnetization.
LoadedScene parse_scene(std::string_view toml_text, const std::string& source_name,
                        const std::vector<std::string>& overrides = {});

}  // namespace mrf
