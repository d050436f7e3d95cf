// The tools' documented exit codes (docs/tools.md, docs/renderer.md, examples/tools/support/
// tool_main.hpp): 0 success, 1 bad input (a resoct::Error), 2 usage error, 3 anything else; each
// failure is one line on stderr, and an output that existed before a failed run is left
// byte-identical (no temporary file left beside it either).

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "core/io/store/test_brick_store_util.hpp"
#include "support/generated_data.hpp"
#include "support/sanitized.hpp"
#include "support/tool_process.hpp"

using resoct::test::shell_quote;
using resoct::test::slurp;
using resoct::test::TempDir;
using resoct::test::ToolRun;

namespace {

constexpr int kOk = 0, kBadInput = 1, kUsage = 2, kOther = 3;

/// What a previous, successful run left at an output path.
const std::string kPrevious = "previous output: must survive a failed run byte for byte\n";

std::size_t count_of(const std::string& s, const std::string& needle) {
  std::size_t n = 0;
  for (std::size_t at = s.find(needle); at != std::string::npos; at = s.find(needle, at + 1)) ++n;
  return n;
}

/// The last line of `s`, without its newline.
std::string last_line(std::string s) {
  if (!s.empty() && s.back() == '\n') s.pop_back();
  return s.substr(s.rfind('\n') + 1);
}

/// A directory with inputs and pre-existing outputs; `@DIR@` in arguments names it.
class ToolExitCodes : public ::testing::Test {
 protected:
  std::string expand(std::string args) const {
    for (std::size_t at; (at = args.find("@DIR@")) != std::string::npos;) {
      args.replace(at, 5, dir_.path().string());
    }
    return args;
  }
  void put(const std::string& name, const std::string& text) const {
    resoct::test::write_bytes(dir_.file(name), std::vector<std::uint8_t>(text.begin(), text.end()));
  }
  std::vector<std::string> entries() const {
    auto e = dir_.entries();
    std::sort(e.begin(), e.end());
    return e;
  }

  /// Runs `tool args`, expects exit code `code`, and for a failure one error line on stderr,
  /// the last, "<tool>: error [<kind>]..." containing `needle` (progress lines such as
  /// "reading X" may come before it), nothing on stdout, every pre-existing output unchanged
  /// and no file added to or removed from the directory.
  void expect_exit(const std::string& tool, const std::string& name, const std::string& args,
                   int code, const std::string& needle, const std::vector<std::string>& outputs) {
    const std::string a = expand(args);
    SCOPED_TRACE(name + " " + a);
    for (const std::string& o : outputs) put(o, kPrevious);
    const std::vector<std::string> before = entries();
    const ToolRun r = resoct::test::run_tool_process(dir_.path().string(), tool, a);
    EXPECT_EQ(r.exit_code, code) << r.err;
    EXPECT_EQ(count_of(r.err, ": error"), 1u) << r.err;
    const std::string last = last_line(r.err);
    const std::string kind = code == kUsage ? "usage" : "";
    EXPECT_EQ(last.rfind(name + ": error [" + kind, 0), 0u) << r.err;
    EXPECT_NE(last.find(expand(needle)), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    for (const std::string& o : outputs) {
      EXPECT_EQ(slurp(dir_.file(o)), kPrevious) << o << " changed";
    }
    EXPECT_EQ(entries(), before) << "a file appeared or vanished";
  }

  TempDir dir_;
};

// A detached NRRD header naming a system file: bad input for every tool (docs/formats.md).
const std::string kHostileHeader =
    "NRRD0004\ntype: uchar\ndimension: 1\nsizes: 4\nencoding: raw\ndata file: /etc/passwd\n";

TEST_F(ToolExitCodes, ConvertBadInputIs1AndLeavesTheOldStore) {
  const std::string c = RESOCT_CONVERT;
  put("short.raw", std::string(100, 'x'));
  put("evil.nhdr", kHostileHeader);
  const std::vector<std::string> out = {"out.rbs"};
  expect_exit(c, "resoct-convert", "@DIR@/missing.raw @DIR@/out.rbs --dims 4x4x4 --type u8",
              kBadInput, "@DIR@/missing.raw", out);
  expect_exit(c, "resoct-convert", "@DIR@/short.raw @DIR@/out.rbs --dims 8x8x8 --type u8",
              kBadInput, "error [truncated]: @DIR@/short.raw", out);
  expect_exit(c, "resoct-convert", "procedural:tubes:32x32x32 @DIR@/out.rbs --brick 2", kBadInput,
              "--brick", out);
  expect_exit(c, "resoct-convert", "procedural:nosuch @DIR@/out.rbs", kBadInput, "nosuch", out);
  expect_exit(c, "resoct-convert", "@DIR@/evil.nhdr @DIR@/out.rbs", kBadInput,
              "error [invalid_argument]: @DIR@/evil.nhdr: NRRD field 'data file' '/etc/passwd'",
              out);
}

TEST_F(ToolExitCodes, ConvertFailingWhileWritingLeavesTheOldStore) {
  // A store whose payload is damaged opens fine (header, index and metadata are intact) and
  // fails at a brick's checksum in the middle of writing: the temporary file is removed and
  // the old output stays.
  const std::string in = dir_.file("in.rbs");
  ASSERT_EQ(resoct::test::run_tool_process(
                dir_.path().string(), RESOCT_CONVERT,
                "procedural:turbulence:64x64x64 " + shell_quote(in) + " --brick 16")
                .exit_code,
            kOk);
  auto bytes = resoct::test::read_bytes(in);
  namespace L = resoct::test::layout;
  const std::uint64_t payload = resoct::test::get_le(bytes, L::payload_offset, 8);
  const std::uint64_t size = resoct::test::get_le(bytes, L::payload_size, 8);
  ASSERT_GT(size, 16u);
  for (std::uint64_t i = payload; i < payload + size; i += 97) bytes.at(i) ^= 0x5a;
  resoct::test::write_bytes(in, bytes);
  expect_exit(RESOCT_CONVERT, "resoct-convert", "@DIR@/in.rbs @DIR@/out.rbs --threads 2", kBadInput,
              "@DIR@/in.rbs", {"out.rbs"});
}

TEST_F(ToolExitCodes, ConvertUsageErrorIs2AndLeavesTheOldStore) {
  const std::string c = RESOCT_CONVERT;
  const std::vector<std::string> out = {"out.rbs"};
  expect_exit(c, "resoct-convert", "procedural:tubes:32x32x32 @DIR@/out.rbs --no-such-option",
              kUsage, "--no-such-option", out);
  expect_exit(c, "resoct-convert", "procedural:tubes:32x32x32 @DIR@/out.rbs --threads many", kUsage,
              "many", out);
  expect_exit(c, "resoct-convert", "procedural:tubes:32x32x32 @DIR@/out.rbs --halo", kUsage,
              "--halo", out);
  expect_exit(c, "resoct-convert", "procedural:tubes:32x32x32", kUsage, "output", out);
}

TEST_F(ToolExitCodes, ConvertSuccessIs0AndReplacesTheOldStore) {
  put("out.rbs", kPrevious);
  const ToolRun r = resoct::test::run_tool_process(
      dir_.path().string(), RESOCT_CONVERT,
      "procedural:ramp:16x16x16 " + shell_quote(dir_.file("out.rbs")) + " --brick 8");
  EXPECT_EQ(r.exit_code, kOk) << r.err;
  EXPECT_NE(slurp(dir_.file("out.rbs")), kPrevious);
}

TEST_F(ToolExitCodes, ConvertOutOfMemoryIs3) {
#if RESOCT_TEST_SANITIZED
  GTEST_SKIP() << "sanitizer runtimes reserve more address space than the limit allows";
#endif
  // Anything but a resoct::Error or a usage error: here std::bad_alloc, from an address space
  // limit (400 MB) below two 520^3-voxel brick buffers (140 MB each, --brick 512 --halo 4), the
  // second allocated by the writer's worker thread. That allocation used to escape the thread
  // and abort the tool (exit 134, temporary file left behind).
  put("out.rbs", kPrevious);
  const ToolRun r = resoct::test::run_tool_process(
      dir_.path().string(), "/bin/sh",
      "-c " + shell_quote("ulimit -v 400000 && exec " + shell_quote(RESOCT_CONVERT) +
                          " procedural:ramp:2048x2048x2048 " + shell_quote(dir_.file("out.rbs")) +
                          " --brick 512 --halo 4 --threads 1"));
  EXPECT_EQ(r.exit_code, kOther) << r.err;
  EXPECT_EQ(last_line(r.err), "resoct-convert: error [out_of_memory]: host memory exhausted")
      << r.err;
  EXPECT_EQ(slurp(dir_.file("out.rbs")), kPrevious);
  EXPECT_EQ(entries(), (std::vector<std::string>{"out.rbs"}));
}

TEST_F(ToolExitCodes, ConvertOnAFullDiskIs1AndLeavesTheOldStore) {
  // A full disk, as a process file-size limit (RLIMIT_FSIZE, 100 blocks of 512 bytes under
  // /bin/sh) below the store's size, with SIGXFSZ ignored so that the write fails with EFBIG
  // instead of killing the tool: an I/O error naming the file and the offset, the temporary
  // file removed, the old store intact.
#if RESOCT_TEST_TSAN
  GTEST_SKIP() << "ThreadSanitizer's runtime faults (SIGBUS in its shadow memory) under a "
                  "file-size limit, before main";
#endif
  put("out.rbs", kPrevious);
  const ToolRun r = resoct::test::run_tool_process(
      dir_.path().string(), "/bin/sh",
      "-c " + shell_quote("trap '' XFSZ; ulimit -f 100 && exec " + shell_quote(RESOCT_CONVERT) +
                          " procedural:turbulence:64x64x64 " + shell_quote(dir_.file("out.rbs")) +
                          " --brick 16 --threads 1"));
  EXPECT_EQ(r.exit_code, kBadInput) << r.err;
  const std::string last = last_line(r.err);
  EXPECT_EQ(last.rfind("resoct-convert: error [io]: " + dir_.file("out.rbs") + ".tmp-", 0), 0u)
      << r.err;
  EXPECT_NE(last.find(": offset "), std::string::npos) << r.err;
  EXPECT_NE(last.find(": write failed"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(dir_.file("out.rbs")), kPrevious);
  EXPECT_EQ(entries(), (std::vector<std::string>{"out.rbs"}));
}

TEST_F(ToolExitCodes, ConvertIntoAReadOnlyDirectoryIs1AndLeavesTheOldStore) {
  // A directory the tool may not write (mode 0555). Root ignores directory permissions through
  // CAP_DAC_OVERRIDE, so under root (CI) the tool runs with that capability (and its relatives)
  // dropped from its bounding set: still uid 0, but held to the permission bits like any user.
  put("out.rbs", kPrevious);
  namespace fs = std::filesystem;
  fs::permissions(dir_.path(), fs::perms::owner_write | fs::perms::group_write,
                  fs::perm_options::remove);
  const std::string drop =
      ::geteuid() == 0 ? "setpriv --bounding-set=-dac_override,-dac_read_search,-fowner -- " : "";
  const ToolRun r = resoct::test::run_tool_process(
      dir_.path().string(), "/bin/sh",
      "-c " + shell_quote("exec " + drop + shell_quote(RESOCT_CONVERT) +
                          " procedural:turbulence:32x32x32 " + shell_quote(dir_.file("out.rbs")) +
                          " --brick 16 --threads 1"));
  fs::permissions(dir_.path(), fs::perms::owner_write, fs::perm_options::add);
  EXPECT_EQ(r.exit_code, kBadInput) << r.err;
  EXPECT_EQ(last_line(r.err), "resoct-convert: error [io]: " + dir_.file("out.rbs") +
                                  ": offset 0: cannot create a temporary file next to it: "
                                  "Permission denied")
      << r.err;
  EXPECT_EQ(slurp(dir_.file("out.rbs")), kPrevious);
  EXPECT_EQ(entries(), (std::vector<std::string>{"out.rbs"}));
}

TEST_F(ToolExitCodes, InfoExitCodes) {
  const std::string i = RESOCT_INFO;
  put("readme.txt", "hello\n");
  put("evil.nhdr", kHostileHeader);
  expect_exit(i, "resoct-info", "@DIR@/missing.rbs", kBadInput, "@DIR@/missing.rbs", {});
  expect_exit(i, "resoct-info", "@DIR@/readme.txt --json", kBadInput, "@DIR@/readme.txt", {});
  expect_exit(i, "resoct-info", "@DIR@/evil.nhdr", kBadInput,
              "@DIR@/evil.nhdr: NRRD field 'data file' '/etc/passwd' is absolute", {});
  expect_exit(i, "resoct-info", "procedural:tubes --no-such-option", kUsage, "--no-such-option",
              {});
  expect_exit(i, "resoct-info", "", kUsage, "source", {});
  const ToolRun ok =
      resoct::test::run_tool_process(dir_.path().string(), i, "procedural:tubes:32x32x32 --json");
  EXPECT_EQ(ok.exit_code, kOk) << ok.err;
}

std::string scene(const std::string& name) {
  return std::string(RESOCT_SOURCE_DIR) + "/examples/scenes/" + name + ".json";
}

/// A quick render of `volume` writing out.png and stats.json; `stats` replaces the stats path
/// (CLI11 refuses an option given twice, so overrides cannot simply be appended).
std::string render(const std::string& volume, const std::string& extra = "",
                   const std::string& stats = "@DIR@/stats.json", const std::string& width = "24") {
  return "--volume " + volume + " --scene " + shell_quote(scene("tubes")) + " --width " + width +
         " --height 16 --frames 1 --threads 0 --out @DIR@/out.png --stats " + stats + extra;
}

TEST_F(ToolExitCodes, RenderBadInputIs1AndLeavesTheOldOutputs) {
  const std::string t = RESOCT_RENDER;
  put("evil.nhdr", kHostileHeader);
  const std::vector<std::string> out = {"out.png", "stats.json"};
  const std::string ok = "procedural:tubes:32x32x32";
  expect_exit(t, "resoct-render", render("@DIR@/absent.rbs"), kBadInput, "@DIR@/absent.rbs", out);
  expect_exit(t, "resoct-render", render("procedural:nosuch"), kBadInput, "nosuch", out);
  expect_exit(t, "resoct-render", render("@DIR@/evil.nhdr"), kBadInput,
              "@DIR@/evil.nhdr: NRRD field 'data file' '/etc/passwd'", out);
  expect_exit(t, "resoct-render", render(ok, " --mode fastest"), kBadInput, "mode", out);
  expect_exit(t, "resoct-render", render(ok, " --cache-mb 0"), kBadInput, "cache-mb", out);
  expect_exit(t, "resoct-render", render(ok, " --skip-min-samples -1"), kBadInput,
              "skip-min-samples", out);
  expect_exit(t, "resoct-render",
              "--volume " + ok + " --scene @DIR@/missing.json --frames 1 --out @DIR@/out.png",
              kBadInput, "@DIR@/missing.json", out);
  // An unwritable --stats fails before rendering, so the PNG is not replaced either.
  expect_exit(t, "resoct-render", render(ok, "", "@DIR@/no/such/dir/s.json"), kBadInput,
              "@DIR@/no/such/dir/s.json", out);
}

TEST_F(ToolExitCodes, RenderUsageErrorIs2AndLeavesTheOldOutputs) {
  const std::string t = RESOCT_RENDER;
  const std::vector<std::string> out = {"out.png", "stats.json"};
  const std::string ok = "procedural:tubes:32x32x32";
  expect_exit(t, "resoct-render", render(ok, " --no-such-option"), kUsage, "--no-such-option", out);
  expect_exit(t, "resoct-render", render(ok, "", "@DIR@/stats.json", "wide"), kUsage, "wide", out);
  expect_exit(t, "resoct-render", render(ok, " --converge"), kUsage, "--converge", out);
}

TEST_F(ToolExitCodes, RenderSuccessIs0AndReplacesTheOldOutputs) {
  put("out.png", kPrevious);
  put("stats.json", kPrevious);
  const ToolRun r = resoct::test::run_tool_process(dir_.path().string(), RESOCT_RENDER,
                                                   expand(render("procedural:tubes:32x32x32")));
  EXPECT_EQ(r.exit_code, kOk) << r.err;
  EXPECT_NE(slurp(dir_.file("out.png")), kPrevious);
  EXPECT_NE(slurp(dir_.file("stats.json")), kPrevious);
}

TEST_F(ToolExitCodes, RenderTimepointAndPlayValuesAreChecked) {
  const std::string t = RESOCT_RENDER;
  const std::vector<std::string> out = {"out.png", "stats.json"};
  const std::string ok = "procedural:tubes:32x32x32";  // one timepoint
  expect_exit(t, "resoct-render", render(ok, " --timepoint 1"), kBadInput,
              "parameter 'timepoint': 1 but procedural:tubes:32x32x32 has 1 timepoint (0..0)", out);
  expect_exit(t, "resoct-render", render(ok, " --timepoint -1"), kUsage, "--timepoint", out);
  expect_exit(t, "resoct-render", render(ok, " --timepoint x"), kUsage, "--timepoint", out);
  const auto play = [&](const std::string& range) {
    return "--volume " + ok + " --scene " + shell_quote(scene("tubes")) +
           " --width 8 --height 8 --frames 1 --threads 0 --out @DIR@/t{t}.png --play " + range;
  };
  expect_exit(t, "resoct-render", play("0:1"), kBadInput, "parameter 'play'", out);
  expect_exit(t, "resoct-render", play("1:0"), kBadInput, "FIRST:LAST", out);
  expect_exit(t, "resoct-render", play("0"), kBadInput, "FIRST:LAST", out);
  expect_exit(t, "resoct-render", play("0:0 --timepoint 0"), kUsage, "--play", out);
  // One image per timepoint needs a pattern.
  expect_exit(t, "resoct-render", render(ok, " --play 0:0"), kBadInput, "parameter 'out'", out);
  const ToolRun r =
      resoct::test::run_tool_process(dir_.path().string(), t, expand(render(ok, " --timepoint 0")));
  EXPECT_EQ(r.exit_code, kOk) << r.err;
}

TEST_F(ToolExitCodes, RenderPlaysAnOmeZarrSeriesOneImagePerTimepoint) {
  const std::string data = resoct::test::python_generated_dir(
      RESOCT_BINARY_DIR "/test-data", "ome-zarr", RESOCT_SOURCE_DIR "/tests/data/make_ome_zarr.py");
  ASSERT_FALSE(data.empty());
  // t = 3 timepoints of 6 x 7 x 8 u8 (tests/data/make_ome_zarr.py).
  const std::string volume = shell_quote(data + "/blosc-lz4-shuffle_leu1_small_tzyx.zarr");
  const std::string args = "--volume " + volume + " --scene " + shell_quote(scene("sphere")) +
                           " --width 16 --height 16 --converge --threads 0 --play 0:2"
                           " --out @DIR@/t{t}.png --stats @DIR@/play.json";
  const ToolRun r =
      resoct::test::run_tool_process(dir_.path().string(), RESOCT_RENDER, expand(args));
  ASSERT_EQ(r.exit_code, kOk) << r.err;
  for (const char* f : {"t0.png", "t1.png", "t2.png"}) {
    EXPECT_TRUE(std::filesystem::exists(dir_.file(f))) << f;
  }
  const std::string stats = slurp(dir_.file("play.json"));
  EXPECT_NE(stats.find("\"timepoints\": 3"), std::string::npos) << stats;
  EXPECT_NE(stats.find("\"play\""), std::string::npos) << stats;
  EXPECT_EQ(count_of(stats, "\"converged\": true"), 4u) << stats;  // 3 timepoints + overall
  expect_exit(RESOCT_RENDER, "resoct-render",
              "--volume " + volume + " --scene " + shell_quote(scene("sphere")) +
                  " --frames 1 --threads 0 --timepoint 3 --out @DIR@/out.png",
              kBadInput, "has 3 timepoints (0..2)", {"out.png"});
}

}  // namespace
