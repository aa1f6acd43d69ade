// The sweep archive: finished points' summary.json files kept apart from the
// sweep output, keyed by the scene_id of the scene that produced them.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "mrf/error.hpp"
#include "mrf/io/archive.hpp"
#include "mrf/io/atomic_file.hpp"
#include "mrf/scene/run_series.hpp"
#include "mrf/io/toml_scene.hpp"
#include "mrf/study/sweep.hpp"

namespace mrf {
namespace {

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

ArchiveSync restore_from_archive(const SweepSpec& spec, const std::vector<SweepPoint>& points,
                                 const std::string& out_dir, const std::string& archive_dir) {
  ArchiveSync sync;
  for (const SweepPoint& p : points) {
    const auto entry = std::filesystem::path(archive_dir) / p.dir / "summary.json";
    const auto dir = std::filesystem::path(out_dir) / p.dir;
    if (!std::filesystem::exists(entry) || point_finished(dir.string())) continue;
    const std::string text = read_text(entry);
    const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
    const std::string want = scene_id(load_scene(spec.scene_path, p.sets).config);
    if (j.is_discarded() || !j.contains("scene_id") || !j["scene_id"].is_string() ||
        j["scene_id"].get<std::string>() != want) {
      sync.stale.push_back(p.dir);
      continue;
    }
    std::filesystem::create_directories(dir);
    std::filesystem::remove(dir / "checkpoint.bin");  // the point is finished: its partial run is moot
    write_file_atomic((dir / "summary.json").string(), text);
    ++sync.restored;
  }
  return sync;
}

std::vector<std::string> set_aside_stale(const SweepSpec& spec, const std::vector<SweepPoint>& points,
                                         const std::string& out_dir, bool quiet) {
  std::vector<std::string> moved;
  for (const SweepPoint& p : points) {
    const auto dir = std::filesystem::path(out_dir) / p.dir;
    const auto summary = dir / "summary.json", checkpoint = dir / "checkpoint.bin";
    if (std::filesystem::exists(summary)) {  // a finished run
      const nlohmann::json j = nlohmann::json::parse(read_text(summary), nullptr, false);
      if (j.is_discarded() || !j.contains("scene_id") || !j["scene_id"].is_string()) continue;
      if (j["scene_id"].get<std::string>() == scene_id(load_scene(spec.scene_path, p.sets).config)) continue;
    } else if (std::filesystem::exists(checkpoint)) {  // a run under way, which --resume would refuse
      try {
        ArchiveReader in(checkpoint.string());
        std::string fp;
        in.get(fp);
        if (fp == scene_fingerprint(load_scene(spec.scene_path, p.sets).config)) continue;
      } catch (const NumericalError&) {
        continue;  // a damaged checkpoint: the run's resume says so
      }
    } else {
      continue;
    }
    const auto aside = std::filesystem::path(dir.string() + ".stale");
    std::error_code ec;
    std::filesystem::remove_all(aside, ec);
    std::filesystem::rename(dir, aside, ec);
    if (ec) {
      if (!std::filesystem::exists(dir)) continue;  // another process moved it first
      throw OutputError(dir.string() + ": cannot move a run of another scene aside to " + aside.string() + ": " +
                        ec.message());
    }
    moved.push_back(p.dir);
    if (!quiet)
      std::fprintf(stderr, "mrf sweep: %s holds a run of another scene (scene_id differs): moved to %s; the point "
                           "runs again\n", dir.string().c_str(), aside.string().c_str());
  }
  return moved;
}

void archive_point(const SweepPoint& p, const std::string& out_dir, const std::string& archive_dir) {
  const auto summary = std::filesystem::path(out_dir) / p.dir / "summary.json";
  if (!std::filesystem::exists(summary)) return;
  const auto dir = std::filesystem::path(archive_dir) / p.dir;
  std::filesystem::create_directories(dir);
  write_file_atomic((dir / "summary.json").string(), read_text(summary));
}

}  // namespace mrf
