// The CLI's Unix habits (docs/cli.md): - as INPUT reads standard input (PCD or PLY by content),
// -o - (or --json without -o) puts the JSON report alone on stdout, --outputs none writes
// nothing, a bare `proxseg` prints its usage, every --help lists its options under headings, the
// man page has examples that run and the values of the choice flags, times print for people and a
// failed frame tells no rate.
#include <proxseg/io/cloud_io.hpp>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <regex>
#include <sstream>

#include "human_time.hpp"
#include "support/cli_util.hpp"

namespace {

using cli_test::CliRun;
using cli_test::kCli;
using cli_test::kData;
using cli_test::learn0;
using cli_test::slurp;
namespace fs = std::filesystem;

const fs::path kTmp = fs::path(PROXSEG_TEST_TMP) / "cli_unix";

// A scratch folder of its own for the calling test, made afresh.
fs::path scratch() {
  const fs::path d = kTmp / ::testing::UnitTest::GetInstance()->current_test_info()->name();
  fs::remove_all(d);
  fs::create_directories(d / "work");
  return d;
}

// `sh -c SCRIPT` in dir/work, where `proxseg` is the CLI under test; its output captured in dir.
CliRun sh(const fs::path& dir, const std::string& script) {
  const fs::path bin = dir / "bin";
  fs::create_directories(bin);
  if (!fs::exists(bin / "proxseg")) fs::create_symlink(kCli, bin / "proxseg");
  std::ofstream(dir / "script.sh") << "cd '" << (dir / "work").string() << "' && PATH='"
                                   << bin.string() << "':$PATH && " << script << "\n";
  const std::string out = (dir / "out.txt").string(), err = (dir / "err.txt").string();
  const int status =
      std::system(("sh " + (dir / "script.sh").string() + " >" + out + " 2>" + err).c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The files a command left in dir/work.
std::vector<std::string> files_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir / "work")) names.push_back(e.path().string());
  return names;
}

// A segmentation report without what differs from run to run (the times).
nlohmann::json stable(nlohmann::json report) {
  for (const char* times : {"times_ms", "step_times_ms", "concurrent_times_ms"})
    report.erase(times);
  return report;
}

// learn0 as an ascii PLY (x y z, red green blue), its valid points in order.
void write_ply(const fs::path& path) {
  const proxseg::Frame f = proxseg::read_pcd(learn0());
  std::ostringstream body;
  std::size_t n = 0;
  for (std::size_t i = 0; i < f.size(); ++i)
    if (f.valid(i)) {
      body << f.xyz[i].x() << " " << f.xyz[i].y() << " " << f.xyz[i].z() << " " << int(f.rgb[i][0])
           << " " << int(f.rgb[i][1]) << " " << int(f.rgb[i][2]) << "\n";
      ++n;
    }
  std::ofstream(path) << "ply\nformat ascii 1.0\nelement vertex " << n
                      << "\nproperty float x\nproperty float y\nproperty float z\n"
                         "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                         "end_header\n"
                      << body.str();
}

TEST(CliUnix, DashReadsAPcdOrAPlyFromStandardInputByContent) {
  const fs::path d = scratch();
  const std::string pcd = learn0();
  const fs::path ply = d / "cloud-without-extension";
  write_ply(ply);
  for (const std::string& file : {pcd, ply.string()}) {
    SCOPED_TRACE(file);
    const std::string named = file == pcd ? pcd : (d / "cloud.ply").string();
    if (file != pcd) fs::copy_file(ply, named, fs::copy_options::overwrite_existing);
    const CliRun piped = sh(d, "cat '" + file + "' | proxseg segment - --outputs json -o -");
    ASSERT_EQ(piped.code, 0) << piped.err;
    const CliRun by_name = sh(d, "proxseg segment '" + named + "' --json");
    ASSERT_EQ(by_name.code, 0) << by_name.err;
    EXPECT_EQ(stable(nlohmann::json::parse(piped.out)), stable(nlohmann::json::parse(by_name.out)));
  }
}

TEST(CliUnix, StandardInputThatIsNoCloudIsRefusedNamingIt) {
  const fs::path d = scratch();
  std::ofstream(d / "garbage.txt") << "hello\nworld\n";
  std::string truncated = slurp(learn0());
  truncated.resize(truncated.size() / 2);
  std::ofstream(d / "half.pcd", std::ios::binary) << truncated;
  const std::pair<std::string, std::string> cases[] = {
      {"proxseg segment - -o out < ../garbage.txt", "<stdin>: is neither a PCD nor a PLY cloud"},
      {"proxseg segment - -o out < /dev/null", "<stdin>: is empty"},
      {"proxseg segment - -o out < ../half.pcd", "<stdin>: binary"},
      // Endless input that is no cloud: refused from its first bytes, not read to its end.
      {"cat /dev/zero | proxseg segment - -o out", "<stdin>: is neither"},
      {"printf 'ply\\nformat ascii 1.0\\nelement vertex 2\\nproperty float "
       "x\\nend_header\\n1\\n2\\n' "
       "| proxseg segment - -o out",
       "<stdin>: PLY vertex element has no x, y and z"},
  };
  for (const auto& [script, message] : cases) {
    SCOPED_TRACE(script);
    const CliRun r = sh(d, script);
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_TRUE(has(r.err, "proxseg: error: " + message)) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(d / "work/out.pcd"));
  }
}

TEST(CliUnix, DashIsRefusedWhereStandardInputMakesNoSense) {
  const fs::path d = scratch();
  const std::string frames = kData + "/ycbv/frames/";
  const std::pair<std::string, std::string> cases[] = {
      {"proxseg segment --batch - -o out", "--batch takes a file here, not - (standard input)"},
      {"proxseg segment --colour - --depth " + frames + "000004-depth.png --meta " + frames +
           "000004-meta.json -o out",
       "--colour takes a file here, not - (standard input): an RGB-D pair is two image files"},
      {"proxseg eval-seg - " + learn0(), "TRUTH takes a file here, not - (standard input)"},
      {"proxseg db add db --name x - -", "- (standard input) holds one view"},
  };
  for (const auto& [script, message] : cases) {
    SCOPED_TRACE(script);
    const CliRun r = sh(d, script + " < " + learn0());
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_TRUE(has(r.err, "proxseg: error: " + message)) << r.err;
  }
  EXPECT_TRUE(files_in(d).empty());
}

TEST(CliUnix, TheReportAloneGoesToStandardOutput) {
  const fs::path d = scratch();
  const CliRun dash = sh(d, "proxseg segment " + learn0() + " --outputs json -o -");
  ASSERT_EQ(dash.code, 0) << dash.err;
  EXPECT_TRUE(files_in(d).empty());
  const CliRun plain_dash = sh(d, "proxseg segment " + learn0() + " -o -");  // json implied
  ASSERT_EQ(plain_dash.code, 0) << plain_dash.err;
  const CliRun json = sh(d, "proxseg -q segment " + learn0() + " --json");
  ASSERT_EQ(json.code, 0) << json.err;
  EXPECT_EQ(json.err, "");
  EXPECT_TRUE(files_in(d).empty());
  // The same report as PREFIX.json of a run that writes it.
  ASSERT_EQ(sh(d, "proxseg segment " + learn0() + " --outputs json -o file").code, 0);
  const nlohmann::json file = nlohmann::json::parse(slurp(d / "work/file.json"));
  for (const CliRun* r : {&dash, &plain_dash, &json})
    EXPECT_EQ(stable(nlohmann::json::parse(r->out)), stable(file));
  // A report that cannot be written out is an error, not a silent loss.
  const CliRun full = sh(d, "proxseg segment " + learn0() + " -o - > /dev/full");
  EXPECT_EQ(full.code, 1);
  EXPECT_TRUE(has(full.err, "proxseg: error: <stdout>: write error")) << full.err;
}

TEST(CliUnix, FilesAskedForStandardOutputAreAUsageErrorThatSaysWhy) {
  const fs::path d = scratch();
  const std::string in = " " + learn0();
  const std::pair<std::string, std::string> cases[] = {
      {"segment" + in + " --outputs png -o -",
       "-o - writes only the JSON report, to stdout: --outputs png are files"},
      {"segment" + in + " --outputs pcd,json -o -", "--outputs pcd are files"},
      {"segment" + in + " --outputs none -o -", "which --outputs none leaves out"},
      {"segment" + in + " --outputs png --json", "--outputs png: files need a prefix"},
      {"segment" + in, "--output is required: -o PREFIX for the files, -o - (or --json)"},
      {"segment --batch " + kData + "/mosd/learn -o -", "-o -: a batch writes a folder"},
      {"recognize --db db" + in + " --outputs pcd,png -o -", "--outputs pcd,png are files"},
  };
  for (const auto& [args, message] : cases) {
    SCOPED_TRACE(args);
    const CliRun r = sh(d, "proxseg " + args);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(r.err.rfind("proxseg: error: ", 0), 0u) << r.err;
    EXPECT_TRUE(has(r.err, message)) << r.err;
    EXPECT_EQ(r.out, "");
  }
  EXPECT_TRUE(files_in(d).empty());
}

TEST(CliUnix, OutputsNoneComputesAndWritesNothing) {
  const fs::path d = scratch();
  CliRun r = sh(d, "proxseg segment " + learn0() + " --outputs none");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(std::regex_match(
      r.out, std::regex(learn0() + ": [0-9]+ surfaces?, [0-9]+ candidates?, [0-9.]+ (ms|s)\n")))
      << r.out;
  r = sh(d, "proxseg segment " + learn0() + " --outputs none -o kept/none");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.rfind(learn0() + ": ", 0), 0u) << r.out;
  r = sh(d, "proxseg segment " + learn0() + " --outputs none --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::parse(r.out).contains("selection"));
  EXPECT_TRUE(files_in(d).empty());
}

TEST(CliUnix, RecognizeTakesStandardInputAndPrintsTheReportAlone) {
  const fs::path d = scratch();
  const std::string milk = kData + "/pcl/milk.pcd";
  const CliRun add = sh(d, "proxseg db add db --name milk - < " + milk);
  ASSERT_EQ(add.code, 0) << add.err;
  EXPECT_TRUE(has(add.err, "from <stdin>")) << add.err;
  const CliRun r = sh(d, "proxseg recognize --db db --object - -o - < " + milk);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  EXPECT_EQ(report["input"], "<stdin>") << report.dump(2).substr(0, 400);
  ASSERT_EQ(report["candidates"].size(), 1u);
  EXPECT_EQ(report["candidates"][0]["name"], "milk");
  EXPECT_EQ(files_in(d).size(), 1u);  // the database only
}

TEST(CliUnix, ACommandOfCommandsAloneShowsItsUsage) {
  const fs::path d = scratch();
  for (const std::string args : {"", "-q", "db"}) {
    SCOPED_TRACE(args);
    const CliRun r = sh(d, "proxseg " + args);
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(r.out, "");  // stdout is for results
    const std::string usage = args == "db" ? "Usage: proxseg db" : "Usage: proxseg";
    EXPECT_TRUE(has(r.err, usage)) << r.err;
    EXPECT_TRUE(has(r.err, "Subcommands:")) << r.err;
    for (const std::string& command :
         args == "db" ? std::vector<std::string>{"add", "render", "info", "check"}
                      : std::vector<std::string>{"segment", "recognize", "db", "view", "synth"})
      EXPECT_TRUE(std::regex_search(r.err, std::regex("\n  " + command + " "))) << command;
    EXPECT_FALSE(has(r.err, "A subcommand is required")) << r.err;
    EXPECT_TRUE(has(r.err, "proxseg: error: give a command")) << r.err;
  }
}

// The headings of a --help, in order.
std::vector<std::string> headings(const std::string& help) {
  std::vector<std::string> found;
  std::smatch m;
  for (std::string rest = help; std::regex_search(rest, m, std::regex("\n([A-Z][a-z ]+):\n"));
       rest = "\n" + m.suffix().str())
    found.push_back(m[1]);
  return found;
}

TEST(CliUnix, EveryHelpListsItsOptionsUnderHeadings) {
  const fs::path d = scratch();
  for (const std::string command :
       {"", "segment", "recognize", "summary", "params", "view", "synth", "eval-seg", "db",
        "db add", "db render", "db info", "db check", "db remove", "db rename", "db upgrade"}) {
    SCOPED_TRACE(command);
    const CliRun r = sh(d, "proxseg " + command + " --help");
    ASSERT_EQ(r.code, 0) << r.err;
    const std::vector<std::string> h = headings(r.out);
    EXPECT_EQ(std::count(h.begin(), h.end(), "Options"), 0) << r.out;  // none left ungrouped
    ASSERT_FALSE(h.empty()) << r.out;
    EXPECT_EQ(h.back() == "Subcommands" ? h[h.size() - 2] : h.back(), "Help") << r.out;
    std::stringstream lines(r.out);
    bool under_heading = false;
    for (std::string line; std::getline(lines, line);) {
      if (std::regex_match(line, std::regex("[A-Z][a-z ]+:"))) under_heading = true;
      if (line.rfind("  -", 0) == 0) {
        EXPECT_TRUE(under_heading) << line;
      }
    }
  }
  const std::vector<std::string> scene = {"Positionals", "Input",      "Output",
                                          "Batch",       "Parameters", "Segmentation parameters"};
  std::vector<std::string> segment = scene, recognize = scene;
  segment.insert(segment.end(), {"Threads and memory", "Help"});
  recognize.insert(recognize.end(), {"Recognition parameters", "Threads and memory", "Help"});
  EXPECT_EQ(headings(sh(d, "proxseg segment --help").out), segment);
  EXPECT_EQ(headings(sh(d, "proxseg recognize --help").out), recognize);
}

TEST(CliUnix, TheInputsHelpSaysTheSpellingOfTheFlags) {
  const fs::path d = scratch();
  for (const std::string command : {"segment", "recognize"}) {
    const std::string help = sh(d, "proxseg " + command + " --help").out;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(help, m, std::regex("\n  input [^\n]*(\n     [^\n]*)*"))) << help;
    const std::string input = m[0];
    EXPECT_TRUE(has(input, "--colour and --depth")) << input;
    EXPECT_TRUE(has(input, "- for standard input")) << input;
    EXPECT_FALSE(has(input, "--color")) << input;
  }
}

// The man page as scripts/cli-docs.py makes it from the CLI's --help, as text.
std::string man_page(const fs::path& d) {
  const std::string script = std::string(PROXSEG_SOURCE_DIR) + "/scripts/cli-docs.py";
  const CliRun r =
      sh(d, "python3 " + script + " " + kCli + " ../share && gzip -dc ../share/proxseg.1.gz");
  EXPECT_EQ(r.code, 0) << r.err;
  return r.out;
}

TEST(CliUnix, TheManPageHasExamplesAndTheValuesOfTheChoices) {
  const fs::path d = scratch();
  const std::string page = man_page(d);
  ASSERT_TRUE(has(page, "\n.SH EXAMPLES\n")) << page;
  const std::string examples = page.substr(page.find("\n.SH EXAMPLES\n"));
  for (const std::string use : {"proxseg synth", "proxseg segment", "proxseg recognize",
                                "proxseg db add", "\\-\\-batch", "proxseg view"})
    EXPECT_TRUE(has(examples, use)) << use;
  // An option's entry: its name, its type with the values, its help.
  const auto entry = [&](const std::string& flag) {
    const std::size_t at = page.find("\\fB" + flag + "\\fR");
    return at == std::string::npos ? std::string() : page.substr(at, page.find(".TP", at) - at);
  };
  EXPECT_TRUE(has(entry("\\-\\-preset"), "{default,paper}")) << entry("\\-\\-preset");
  for (const std::string kind : {"labels", "pcd", "png", "json", "html", "all", "none"})
    EXPECT_TRUE(has(entry("\\-\\-outputs"), kind)) << entry("\\-\\-outputs");
  EXPECT_TRUE(has(entry("\\-\\-mrf\\-method"), "{swap | expansion}"))
      << entry("\\-\\-mrf\\-method");
  EXPECT_TRUE(has(page, "\\fIInput:\\fR")) << "the headings of the options";
  // The examples that need nothing but proxseg (those before the first `db add`) run as written.
  std::stringstream lines(examples.substr(0, examples.find("proxseg db add")));
  int ran = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("proxseg ", 0) != 0) continue;
    line = std::regex_replace(line, std::regex("\\\\-"), "-");
    const CliRun r = sh(d, line);
    EXPECT_EQ(r.code, 0) << line << "\n" << r.err;
    ++ran;
  }
  EXPECT_GE(ran, 5);
  EXPECT_TRUE(nlohmann::json::parse(slurp(d / "work/report.json")).contains("selection"));
  EXPECT_TRUE(fs::exists(d / "work/out/scene.html"));
}

TEST(CliUnix, TimesPrintWithThreeFiguresOrMinutes) {
  using cli::human_time;
  EXPECT_EQ(human_time(0.0516183), "51.6 ms");
  EXPECT_EQ(human_time(0.00042), "0.42 ms");
  EXPECT_EQ(human_time(0.5164), "516 ms");
  EXPECT_EQ(human_time(0.9996), "1.00 s");  // not "1000 ms"
  EXPECT_EQ(human_time(1.234), "1.23 s");
  EXPECT_EQ(human_time(12.34), "12.3 s");
  EXPECT_EQ(human_time(59.97), "1 min 00 s");
  EXPECT_EQ(human_time(125.2), "2 min 05 s");
  EXPECT_EQ(human_time(3725), "1 h 02 min");
  EXPECT_EQ(human_time(-1), "?");
  EXPECT_EQ(cli::human_ms(51.6183), "51.6 ms");
  // The CLI's summary line.
  const fs::path d = scratch();
  const CliRun r = sh(d, "proxseg segment " + learn0() + " -o scene");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(std::regex_search(r.out, std::regex(", ([0-9]\\.[0-9]{2}|[0-9]{2}\\.[0-9]|[0-9]{3}) "
                                                  "ms\n$|, [0-9.]+ s\n$")))
      << r.out;
}

TEST(CliUnix, AFailedFrameTellsNoRate) {
  const fs::path d = scratch();
  fs::create_directories(d / "work/in");
  std::ofstream(d / "work/in/broken.pcd") << "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\n";
  const CliRun r = sh(d, "proxseg segment --batch in -o out --threads 1");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_TRUE(has(r.err, "broken (failed)")) << r.err;
  EXPECT_FALSE(has(r.err, "frames/s")) << r.err;
  // With a good frame beside it, the rate counts the good one.
  fs::copy_file(learn0(), d / "work/in/good.pcd");
  const CliRun both = sh(d, "proxseg segment --batch in -o out2 --threads 1");
  EXPECT_EQ(both.code, 1) << both.err;
  EXPECT_TRUE(std::regex_search(both.err, std::regex("good  [0-9.]+ frames/s, ETA 0.00 ms")))
      << both.err;
}

}  // namespace
