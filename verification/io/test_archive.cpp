// Checkpoint archives (io/archive.hpp) and their checksum (io/checksum.hpp):
// - CRC-32 gives the published check values of the ISO-HDLC / zlib CRC;
// - every kind of field round-trips bit for bit, in the documented layout;
// - a foreign, old, truncated, byte-swapped or damaged file is refused, with
//   its reason, before any field is read, and so is a read past the payload;
// - end to end, `--resume` refuses a run's checkpoint with one flipped byte
//   and leaves the run's files as they were; the restored byte resumes.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "mrf/error.hpp"
#include "mrf/io/archive.hpp"
#include "mrf/io/checksum.hpp"
#include "mrf/scene/run.hpp"
#include "support/files.hpp"

namespace mrf {
namespace {

using test::read_bytes;
using test::TempDir;
using test::write_bytes;

// The check value of CRC-32/ISO-HDLC in Greg Cook's CRC catalogue
// (reveng.sourceforge.io), at compile time: the table and the loop are constexpr.
static_assert(crc32("123456789") == 0xCBF43926u);

// The catalogue's check value and the examples of the Wikipedia article on CRC-32 checks.
TEST(Crc32, GivesThePublishedCheckValues) {
  EXPECT_EQ(crc32(""), 0x00000000u);
  EXPECT_EQ(crc32("a"), 0xE8B7BE43u);
  EXPECT_EQ(crc32("123456789"), 0xCBF43926u);
  EXPECT_EQ(crc32("The quick brown fox jumps over the lazy dog"), 0x414FA339u);
}

TEST(Crc32, ContinuesAcrossPieces) {
  EXPECT_EQ(crc32("56789", crc32("1234")), crc32("123456789"));
  EXPECT_EQ(crc32("", crc32("abc")), crc32("abc"));
}

struct Counters {  // a trivially copyable struct, stored as its bytes
  long a = 0;
  double b = 0;
  int c = 0;
};

// A struct serialised through io(), both directions from one field list.
struct Pair {
  std::vector<double> w;
  Counters k;
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& s) {
    ar.io(s.w, s.k);
  }
};

std::string refusal(const std::filesystem::path& p) {
  try {
    ArchiveReader in(p.string());
  } catch (const NumericalError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// A small valid archive: a string, a double vector and a scalar.
std::string small_archive(const std::filesystem::path& p) {
  ArchiveWriter out(p.string());
  out.put(std::string("fingerprint"));
  out.put(std::vector<double>{1.5, -2.25, 3e-300, 7.0});
  out.put(42L);
  out.close();
  return read_bytes(p);
}

// Rewrites the stored checksum, so that only the field changed by a test is wrong.
void reseal(std::string& bytes) {
  const std::uint32_t c = crc32(std::string_view(bytes).substr(0, bytes.size() - 4));
  std::memcpy(bytes.data() + bytes.size() - 4, &c, 4);
}

TEST(Archive, RoundTripsEveryKindOfField) {
  TempDir dir("archive_round_trip");
  const auto p = dir.path() / "a.bin";
  const Vec3 x(1.0 / 3.0, -0.0, 6.02e23);
  const std::vector<Vec3> xs{Vec3(1, 2, 3), Vec3(-4e-9, 5e9, 0.1)};
  const std::vector<long> ks{1, -2, 1L << 40};
  const std::string text("with a \0 inside", 15);
  const Counters counters{-7, 0.1, 3};
  const Pair pair{{0.5, 0.25}, {1, 2.0, 3}};
  {
    ArchiveWriter out(p.string());
    out.put(2.5);
    out.put(-3L);
    out.put(std::uint64_t{1} << 63);
    out.put(true);
    out.put(counters);
    out.put(x);
    out.put(xs);
    out.put(ks);
    out.put(std::vector<double>{});
    out.put(text);
    out.put(std::string());
    out.io(pair, 9.0);
    EXPECT_FALSE(std::filesystem::exists(p)) << "the writer writes only on close()";
    out.close();
  }
  ArchiveReader in(p.string());
  double d = 0, nine = 0;
  long l = 0;
  std::uint64_t u = 0;
  bool b = false;
  Counters c;
  Vec3 y;
  std::vector<Vec3> ys;
  std::vector<long> ls;
  std::vector<double> empty{1.0};
  std::string s, none = "x";
  Pair q;
  in.io(d, l, u, b, c, y, ys, ls, empty, s, none);  // io() is get() for a reader
  in.io(q, nine);
  EXPECT_EQ(d, 2.5);
  EXPECT_EQ(l, -3L);
  EXPECT_EQ(u, std::uint64_t{1} << 63);
  EXPECT_TRUE(b);
  EXPECT_EQ(std::memcmp(&c, &counters, sizeof c), 0);
  EXPECT_EQ(std::memcmp(y.data(), x.data(), sizeof(Vec3)), 0);  // bits, so -0.0 stays negative
  EXPECT_EQ(ys, xs);
  EXPECT_EQ(ls, ks);
  EXPECT_TRUE(empty.empty());
  EXPECT_EQ(s, text);
  EXPECT_TRUE(none.empty());
  EXPECT_EQ(q.w, pair.w);
  EXPECT_EQ(std::memcmp(&q.k, &pair.k, sizeof q.k), 0);
  EXPECT_EQ(nine, 9.0);
  EXPECT_EQ(in.remaining(), 0u);
  EXPECT_NO_THROW(in.expect_end());
}

// The layout of io/archive.hpp, read back with nothing but memcpy and crc32.
TEST(Archive, WritesTheDocumentedLayout) {
  TempDir dir("archive_layout");
  const std::string bytes = small_archive(dir.path() / "a.bin");
  const std::size_t payload = (8 + 11) + (8 + 4 * 8) + 8;
  ASSERT_EQ(bytes.size(), 24 + payload + 4);
  EXPECT_EQ(bytes.substr(0, 8), std::string("MRFCKPT\0", 8));
  std::uint32_t order = 0, version = 0, crc = 0;
  std::uint64_t length = 0;
  std::memcpy(&order, bytes.data() + 8, 4);
  std::memcpy(&version, bytes.data() + 12, 4);
  std::memcpy(&length, bytes.data() + 16, 8);
  std::memcpy(&crc, bytes.data() + bytes.size() - 4, 4);
  EXPECT_EQ(order, 0x01020304u);
  EXPECT_EQ(version, k_archive_version);
  EXPECT_EQ(version, 11u);
  EXPECT_EQ(length, payload);
  EXPECT_EQ(crc, crc32(std::string_view(bytes).substr(0, bytes.size() - 4)));
}

// Every single flipped byte after the magic word, payload and stored
// checksum included, is caught; in the payload it is the checksum that says so.
TEST(Archive, RefusesAFlippedByteWithTheChecksumMessage) {
  TempDir dir("archive_flip");
  const auto p = dir.path() / "a.bin";
  const std::string good = small_archive(p);
  for (std::size_t i = 8; i < good.size(); ++i) {
    std::string bad = good;
    bad[i] = static_cast<char>(bad[i] ^ 0x10);
    write_bytes(p, bad);
    const std::string why = refusal(p);
    EXPECT_TRUE(contains(why, p.string())) << "byte " << i << ": " << why;
    if (i >= 24) {
      EXPECT_TRUE(contains(why, "corrupt checkpoint: checksum mismatch")) << "byte " << i << ": " << why;
    }
  }
}

TEST(Archive, RefusesATruncatedFileCutAnywhere) {
  TempDir dir("archive_cut");
  const auto p = dir.path() / "a.bin";
  const std::string good = small_archive(p);
  const std::size_t m = good.size();  // cut inside magic, marker, version, length, payload, checksum
  for (std::size_t n : {std::size_t{0}, std::size_t{3}, std::size_t{8}, std::size_t{11}, std::size_t{16},
                        std::size_t{23}, std::size_t{24}, std::size_t{27}, m / 2, m - 5, m - 4, m - 1}) {
    write_bytes(p, good.substr(0, n));
    const std::string why = refusal(p);
    EXPECT_TRUE(contains(why, "truncated checkpoint")) << n << " bytes: " << why;
    EXPECT_TRUE(contains(why, p.string())) << why;
  }
  write_bytes(p, good + "x");
  EXPECT_TRUE(contains(refusal(p), "corrupt checkpoint: size mismatch")) << refusal(p);
}

TEST(Archive, RefusesAFileWithAnotherMagicWord) {
  TempDir dir("archive_magic");
  const auto p = dir.path() / "a.bin";
  std::string bytes = small_archive(p);
  bytes.replace(0, 8, std::string("MRFCKPU\0", 8));
  reseal(bytes);
  write_bytes(p, bytes);
  EXPECT_TRUE(contains(refusal(p), "not an mrf checkpoint")) << refusal(p);
  write_bytes(p, "time_s,strain,stress_total_Pa\n0,0,0\n");
  EXPECT_TRUE(contains(refusal(p), "not an mrf checkpoint")) << refusal(p);
  write_bytes(p, "MRF");  // a prefix of the magic word: cut, not foreign
  EXPECT_TRUE(contains(refusal(p), "truncated checkpoint")) << refusal(p);
}

TEST(Archive, RefusesAnotherFormatVersion) {
  TempDir dir("archive_version");
  const auto p = dir.path() / "a.bin";
  const std::string good = small_archive(p);
  for (std::uint32_t v : {k_archive_version - 1, k_archive_version + 1}) {
    std::string bytes = good;
    std::memcpy(bytes.data() + 12, &v, 4);
    reseal(bytes);
    write_bytes(p, bytes);
    const std::string why = refusal(p);
    EXPECT_TRUE(contains(why, "format version " + std::to_string(v) + ", this build reads " +
                                  std::to_string(k_archive_version) +
                                  ": rerun from the start or use the mrf that wrote it"))
        << why;
  }
}

TEST(Archive, RefusesAFileOfOtherByteOrder) {
  TempDir dir("archive_order");
  const auto p = dir.path() / "a.bin";
  std::string bytes = small_archive(p);
  std::swap(bytes[8], bytes[11]);
  std::swap(bytes[9], bytes[10]);
  reseal(bytes);
  write_bytes(p, bytes);
  EXPECT_TRUE(contains(refusal(p), "written on a machine of other byte order")) << refusal(p);
}

TEST(Archive, RefusesReadingMoreFieldsThanWritten) {
  TempDir dir("archive_more");
  const auto p = dir.path() / "a.bin";
  small_archive(p);
  ArchiveReader in(p.string());
  std::string s;
  std::vector<double> v;
  long l = 0;
  in.get(s);
  in.get(v);
  in.get(l);
  double extra = 0;
  try {
    in.get(extra);
    FAIL() << "read past the payload";
  } catch (const NumericalError& e) {
    EXPECT_TRUE(contains(e.what(), "truncated checkpoint")) << e.what();
  }
  ArchiveReader again(p.string());  // a count read where a scalar was written
  again.get(s);
  again.get(l);
  std::vector<Vec3> xs;
  EXPECT_THROW(again.get(xs), NumericalError);
}

TEST(Archive, RefusesReadingFewerFieldsThanWritten) {
  TempDir dir("archive_fewer");
  const auto p = dir.path() / "a.bin";
  small_archive(p);
  ArchiveReader in(p.string());
  std::string s;
  in.get(s);
  EXPECT_THROW(in.expect_end(), NumericalError);
}

// End to end on the small DEM scene (320 steps): a run stopped at step 200
// after a checkpoint at row 100, its checkpoint damaged in one byte.
TEST(ArchiveResume, RefusesACheckpointWithAFlippedByteAndLeavesTheRunAsItWas) {
  TempDir dir("archive_resume");
  const LoadedScene scene = load_scene(MRF_SOURCE_DIR "/experiments/scenes/small_dem_stokes.toml",
                                       {"drive.mason=1.0", "drive.strain=0.5", "drive.warmup_strain=0.1",
                                        "numerics.integrator=\"verlet_exp\"", "output.frames=0"});
  RunOptions opt;
  opt.out_dir = dir.path().string();
  opt.quiet = true;
  opt.checkpoint_every_rows = 100;
  opt.stop_after_steps = 200;
  EXPECT_THROW(run_scene(scene, opt), RunInterrupted);
  const auto ckpt = dir.path() / "checkpoint.bin";
  ASSERT_TRUE(std::filesystem::exists(ckpt));
  const std::string good = read_bytes(ckpt), series = read_bytes(dir.path() / "timeseries.csv");
  std::string bad = good;
  bad[bad.size() / 2] = static_cast<char>(bad[bad.size() / 2] ^ 0x04);
  write_bytes(ckpt, bad);

  opt.stop_after_steps = 0;
  opt.resume = true;
  try {
    run_scene(scene, opt);
    FAIL() << "resumed from a damaged checkpoint";
  } catch (const NumericalError& e) {
    EXPECT_TRUE(contains(e.what(), "corrupt checkpoint: checksum mismatch")) << e.what();
    EXPECT_TRUE(contains(e.what(), ckpt.string())) << e.what();
  }
  EXPECT_EQ(read_bytes(ckpt), bad);
  EXPECT_EQ(read_bytes(dir.path() / "timeseries.csv"), series) << "a refused resume must not cut the time series";
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "summary.json"));

  write_bytes(ckpt, good);  // the control: the same checkpoint, undamaged, resumes
  const RunSummary s = run_scene(scene, opt);
  EXPECT_GT(s.steps, 200);
  EXPECT_FALSE(std::filesystem::exists(ckpt));
}

}  // namespace
}  // namespace mrf
