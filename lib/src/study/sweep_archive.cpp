// The sweep archive: finished points' summary.json files kept apart from the
// sweep output, keyed by the scene_id of the scene that produced them.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "mrf/error.hpp"
#include "mrf/io/archive.hpp"
#include "mrf/io/atomic_file.hpp"
#include "mrf/io/timeseries.hpp"
#include "mrf/scene/run_series.hpp"
#include "mrf/io/toml_scene.hpp"
#include "mrf/study/point_claim.hpp"
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

bool archive_entry_current(const SweepSpec& spec, const SweepPoint& p, const std::string& archive_dir) {
  const auto entry = std::filesystem::path(archive_dir) / p.dir / "summary.json";
  if (archive_dir.empty() || !std::filesystem::exists(entry)) return false;
  const nlohmann::json j = nlohmann::json::parse(read_text(entry), nullptr, false);
  return !j.is_discarded() && j.contains("scene_id") && j["scene_id"].is_string() &&
         j["scene_id"].get<std::string>() == scene_id(load_scene(spec.scene_path, p.sets).config);
}

ArchiveSync restore_from_archive(const SweepSpec& spec, const std::vector<SweepPoint>& points,
                                 const std::string& out_dir, const std::string& archive_dir, bool claimed) {
  ArchiveSync sync;
  for (const SweepPoint& p : points) {
    const auto entry = std::filesystem::path(archive_dir) / p.dir / "summary.json";
    const auto dir = std::filesystem::path(out_dir) / p.dir;
    const bool finished = point_finished(dir.string());
    // a finished run of the point's scene (not a failure) the archive lacks
    if (finished && std::filesystem::exists(dir / "summary.json") && !point_stale(spec, p, dir) &&
        !archive_entry_current(spec, p, archive_dir)) {
      archive_point(p, out_dir, archive_dir);
      ++sync.archived;
      continue;
    }
    if (!std::filesystem::exists(entry)) continue;
    if (finished) {
      // an entry archived without its window series (before session 25)
      // gets it from the run that wrote it, while that run's folder is here
      if (!std::filesystem::exists(entry.parent_path() / k_window_series_file) &&
          std::filesystem::exists(dir / "summary.json") && read_text(dir / "summary.json") == read_text(entry) &&
          std::filesystem::exists(dir / "timeseries.csv")) {
        archive_point(p, out_dir, archive_dir);
        ++sync.series_added;
      }
      continue;
    }
    if (!archive_entry_current(spec, p, archive_dir)) {
      sync.stale.push_back(p.dir);
      continue;
    }
    const std::unique_ptr<PointClaim> claim = claimed ? nullptr : std::make_unique<PointClaim>(dir);
    if (claim && !claim->owned()) continue;  // not under a run of another process
    const std::string text = read_text(entry);
    std::filesystem::create_directories(dir);
    write_file_atomic((dir / "summary.json").string(), text);
    // the point is finished: the partial run in the folder is moot, and its
    // series must not pass for the archived run's (archive_point takes the
    // folder's timeseries.csv as the summary's)
    for (const char* f : {"checkpoint.bin", "timeseries.csv", "frames.xyz"}) std::filesystem::remove(dir / f);
    ++sync.restored;
  }
  return sync;
}

std::string folder_scene_id(const std::filesystem::path& dir) {
  // summary.json and failure.json carry the scene_id; a run under way has
  // its scene's fingerprint first in the checkpoint
  for (const char* name : {"summary.json", "failure.json"}) {
    if (!std::filesystem::exists(dir / name)) continue;
    const nlohmann::json j = nlohmann::json::parse(read_text(dir / name), nullptr, false);
    return !j.is_discarded() && j.contains("scene_id") && j["scene_id"].is_string() ? j["scene_id"].get<std::string>()
                                                                                     : std::string();
  }
  if (!std::filesystem::exists(dir / "checkpoint.bin")) return {};
  try {
    ArchiveReader in((dir / "checkpoint.bin").string());
    std::string fp;
    in.get(fp);
    return fingerprint_id(fp);
  } catch (const NumericalError&) {
    return {};  // a damaged checkpoint: the run's resume says so
  }
}

bool point_stale(const SweepSpec& spec, const SweepPoint& p, const std::filesystem::path& dir) {
  const std::string have = folder_scene_id(dir);
  return !have.empty() && have != scene_id(load_scene(spec.scene_path, p.sets).config);
}

bool point_finished(const SweepSpec& spec, const SweepPoint& p, const std::string& out_dir) {
  const auto dir = std::filesystem::path(out_dir) / p.dir;
  return point_finished(dir.string()) && !point_stale(spec, p, dir);
}

double point_fraction_left(const SweepSpec& spec, const SweepPoint& p, const std::string& out_dir) {
  const auto dir = std::filesystem::path(out_dir) / p.dir;
  if (point_stale(spec, p, dir)) return 1.0;  // another scene's run: this one starts from zero
  const double strain = load_scene(spec.scene_path, p.sets).config.strain;
  return strain > 0 ? std::clamp(1.0 - point_strain_reached(dir.string()) / strain, 0.0, 1.0) : 1.0;
}

std::vector<std::string> set_aside_stale(const SweepSpec& spec, const std::vector<SweepPoint>& points,
                                         const std::string& out_dir, bool quiet, bool claimed) {
  std::vector<std::string> moved;
  for (const SweepPoint& p : points) {
    const auto dir = std::filesystem::path(out_dir) / p.dir;
    const std::string want = scene_id(load_scene(spec.scene_path, p.sets).config);
    const std::string have = folder_scene_id(dir);
    const auto mine = std::filesystem::path(dir.string() + ".stale-" + want);
    const bool back = !std::filesystem::exists(dir / "summary.json") && std::filesystem::exists(mine / "summary.json");
    if ((have.empty() || have == want) && !back) continue;
    // Folders are moved only under the point's claim: a process running the
    // point (with the other scene's rules) keeps its folder.
    const std::unique_ptr<PointClaim> claim = claimed ? nullptr : std::make_unique<PointClaim>(dir);
    if (claim && !claim->owned()) {
      if (!quiet)
        std::fprintf(stderr, "mrf sweep: %s is being run by %s: not set aside\n", dir.string().c_str(),
                     claim->holder().c_str());
      continue;
    }
    if (!have.empty() && have != want) {
      // kept under the scene it was made for: a later run of that scene
      // replaces it, a return to that scene takes it back (below)
      const auto aside = std::filesystem::path(dir.string() + ".stale-" + have);
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
        std::fprintf(stderr, "mrf sweep: %s holds a run of another scene (scene_id %s, the point's is %s): moved to "
                             "%s; the point runs again\n", dir.string().c_str(), have.c_str(), want.c_str(),
                     aside.string().c_str());
    }
    // A finished run of this very scene set aside earlier comes back.
    if (!std::filesystem::exists(dir / "summary.json") && std::filesystem::exists(mine / "summary.json") &&
        folder_scene_id(mine) == want) {
      std::error_code ec;
      std::filesystem::remove_all(dir, ec);
      std::filesystem::rename(mine, dir, ec);
      if (!ec && !quiet)
        std::fprintf(stderr, "mrf sweep: %s: its finished run of this scene is back from %s\n", dir.string().c_str(),
                     mine.string().c_str());
    }
  }
  return moved;
}

void archive_point(const SweepPoint& p, const std::string& out_dir, const std::string& archive_dir) {
  const auto summary = std::filesystem::path(out_dir) / p.dir / "summary.json";
  if (!std::filesystem::exists(summary)) return;
  const auto dir = std::filesystem::path(archive_dir) / p.dir;
  std::filesystem::create_directories(dir);
  write_file_atomic((dir / "summary.json").string(), read_text(summary));
  // the averaging window's series, for re-estimating the point later
  // (io/timeseries.hpp); a run without one (output.every = 0) keeps none
  const auto series = std::filesystem::path(out_dir) / p.dir / "timeseries.csv";
  const nlohmann::json s = nlohmann::json::parse(read_text(summary), nullptr, false);
  if (std::filesystem::exists(series) && !s.is_discarded() && s.contains("warmup_strain") &&
      s["warmup_strain"].is_number())
    write_file_atomic((dir / k_window_series_file).string(),
                      window_series_text(series.string(), s["warmup_strain"].get<double>()));
}

}  // namespace mrf
