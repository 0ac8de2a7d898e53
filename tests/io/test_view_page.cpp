// The 3D page (io/view_page.hpp) and the batch page (io/batch_page.hpp) as data: the points the
// page embeds decode to the frame's points and ids, the legends are the report's, and bad input
// is an InputError; names become relative, percent-encoded links (page_text.hpp).
// python/tests/test_view.py and tests/page/ load the pages in a browser.
#include <proxseg/core/errors.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/render.hpp>
#include <proxseg/io/batch_page.hpp>
#include <proxseg/io/output.hpp>
#include <proxseg/io/view_page.hpp>

#include <gtest/gtest.h>
#include <zlib.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>

#include "io/page/page_text.hpp"

namespace {

using namespace proxseg;
using nlohmann::json;
namespace fs = std::filesystem;

std::string between(const std::string& text, const std::string& open, const std::string& close) {
  const std::size_t a = text.find(open);
  EXPECT_NE(a, std::string::npos) << open;
  const std::size_t from = a + open.size(), b = text.find(close, from);
  return text.substr(from, b - from);
}

std::string unbase64(const std::string& text) {
  std::string out;
  std::uint32_t bits = 0;
  int count = 0;
  for (char c : text) {
    const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const char* at = c ? std::strchr(digits, c) : nullptr;
    if (!at) continue;  // '=' and white space
    bits = (bits << 6) | static_cast<std::uint32_t>(at - digits);
    if ((count += 6) >= 8) out += static_cast<char>((bits >> (count -= 8)) & 0xff);
  }
  return out;
}

std::string inflated(const std::string& bytes, std::size_t size) {
  std::string out(size, '\0');
  uLongf n = size;
  EXPECT_EQ(uncompress(reinterpret_cast<Bytef*>(out.data()), &n,
                       reinterpret_cast<const Bytef*>(bytes.data()), bytes.size()),
            Z_OK);
  out.resize(n);
  return out;
}

std::uint16_t plane16(const std::string& blob, const json& at, std::size_t i) {
  const std::size_t offset = at[0], n = at[1];
  return static_cast<std::uint8_t>(blob[offset + i]) |
         static_cast<std::uint8_t>(blob[offset + n + i]) << 8;
}

struct Segmented {
  Frame frame = synth_scene(SynthParams{});
  SegmentParams params;
  SegmentResult result = segment(frame, params);
  json report = segmentation_report(frame, params, result);
};

const Segmented& segmented() {
  static const Segmented s;
  return s;
}

TEST(ViewPage, EmbedsTheFramesPointsAndIdsAsThePageDecodesThem) {
  const Segmented& s = segmented();
  const std::string page = view_page(
      s.frame, {{"label", s.result.point_labels}, {"instance", s.result.selection.instance}},
      s.report, {ViewOptions{}.max_points, "synthetic"});
  const json meta = json::parse(between(page, "type=\"application/json\">", "</script>"));
  EXPECT_EQ(meta["title"], "synthetic");
  std::vector<int> valid;
  for (std::size_t i = 0; i < s.frame.size(); ++i)
    if (s.frame.xyz[i].allFinite()) valid.push_back(static_cast<int>(i));
  ASSERT_EQ(meta["points"], valid.size());
  const std::string blob =
      inflated(unbase64(between(page, "type=\"application/octet-stream\">", "</script>")),
               16 * valid.size() + 64);
  for (int a = 0; a < 3; ++a) {
    const double lo = meta["bounds"]["min"][a], step = meta["bounds"]["step"][a];
    std::uint16_t q = 0;
    double worst = 0;
    for (std::size_t i = 0; i < valid.size(); ++i) {
      q = static_cast<std::uint16_t>(q + plane16(blob, meta["arrays"]["position"][a], i));
      worst = std::max(worst, std::abs(lo + q * step - s.frame.xyz[valid[i]][a]));
    }
    EXPECT_LE(worst, step * 0.51 + 1e-7) << "axis " << a;
  }
  for (std::size_t i = 0; i < valid.size(); i += 97) {
    EXPECT_EQ(plane16(blob, meta["arrays"]["instance"], i), s.result.selection.instance[valid[i]]);
    EXPECT_EQ(plane16(blob, meta["arrays"]["label"], i), s.result.point_labels[valid[i]]);
  }
  // Layers: the scene's colours, then the fields; the instances' legend is the report's.
  std::vector<std::string> keys;
  for (const json& l : meta["layers"]) keys.push_back(l["key"]);
  EXPECT_EQ(keys, (std::vector<std::string>{"colour", "label", "instance"}));
  std::set<int> ids, reported;
  for (const json& e : meta["layers"][2]["legend"]) ids.insert(e["id"].get<int>());
  for (const char* kind : {"candidates", "background"})
    for (const json& c : s.report[kind]) reported.insert(c["id"].get<int>());
  EXPECT_EQ(ids, reported);
  EXPECT_EQ(meta["objects"].size(), s.report["candidates"].size());  // their boxes
}

TEST(ViewPage, ShowsEveryKthPointOfLargeCloudsAndSaysSo) {
  const Segmented& s = segmented();
  const std::string page = view_page(s.frame, {}, s.report, {1000, "few"});
  const json meta = json::parse(between(page, "type=\"application/json\">", "</script>"));
  EXPECT_LE(meta["points"].get<int>(), 1000);
  ASSERT_EQ(meta["notes"].size(), 1u);
  EXPECT_NE(meta["notes"][0].get<std::string>().find("th of the"), std::string::npos);
}

TEST(ViewPage, NoTextOfTheReportEndsThePagesScript) {
  const Segmented& s = segmented();
  const std::string page =
      view_page(s.frame, {}, s.report, {ViewOptions{}.max_points, "</script><b>x</b>"});
  EXPECT_EQ(page.find("</script><b>"), std::string::npos);
  EXPECT_NE(page.find("\\u003c/script>\\u003cb>"), std::string::npos);
  // A title that reads like the template's placeholders is shown as it is: the script and the
  // points still go where the template has them.
  const std::string plain = view_page(s.frame, {}, s.report, {ViewOptions{}.max_points, "x"});
  const std::string odd =
      view_page(s.frame, {}, s.report, {ViewOptions{}.max_points, "@JS@ @POINTS@ @HEAD@"});
  EXPECT_NE(odd.find("\"title\":\"@JS@ @POINTS@ @HEAD@\""), std::string::npos);
  EXPECT_EQ(odd.size(), plain.size() + std::string("@JS@ @POINTS@ @HEAD@").size() - 1);
}

// RFC 3986's unreserved characters stay, '/' stays between folders, every other byte is %XX
// (upper-case hex): a scheme's ':', a fragment's '#', a query's '?', '%' itself, space, quotes,
// markup, UTF-8 and bytes that are not UTF-8 alike; and the link always starts with "./".
TEST(ViewPage, RelativeUrlKeepsUnreservedAndPercentEncodesEveryOtherByte) {
  using detail::relative_url;
  EXPECT_EQ(relative_url("learn0.png"), "./learn0.png");
  EXPECT_EQ(relative_url("AZaz09-._~"), "./AZaz09-._~");
  EXPECT_EQ(relative_url("javascript:alert(document.domain).html"),
            "./javascript%3Aalert%28document.domain%29.html");
  EXPECT_EQ(relative_url("a#b?x=1&y;50%"), "./a%23b%3Fx%3D1%26y%3B50%25");
  EXPECT_EQ(relative_url("%41"), "./%2541");  // not "A": an escape in a name is its text
  EXPECT_EQ(relative_url("sp ace\"'<>`\\"), "./sp%20ace%22%27%3C%3E%60%5C");
  EXPECT_EQ(relative_url("\xc3\xbcn\xc3\xaf"), "./%C3%BCn%C3%AF");               // UTF-8: its bytes
  EXPECT_EQ(relative_url(std::string("bad\xff\x00\x7f", 6)), "./bad%FF%00%7F");  // any byte
  EXPECT_EQ(relative_url("video1/d#ir/j:s.png"), "./video1/d%23ir/j%3As.png");
  EXPECT_EQ(relative_url(""), "./");
  // Whatever the bytes, nothing but "./", unreserved characters, '/' and %XX.
  std::string all;
  for (int b = 0; b < 256; ++b) all += static_cast<char>(b);
  const std::string url = relative_url(all);
  ASSERT_EQ(url.compare(0, 2, "./"), 0);
  EXPECT_EQ(url.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789"
                                  "-._~/%",
                                  2),
            std::string::npos);
  EXPECT_EQ(url.size(), 2 + 67 + 3 * (256 - 67));  // 66 unreserved and '/' kept, 189 encoded
}

TEST(ViewPage, BadInputIsAnInputError) {
  const Segmented& s = segmented();
  EXPECT_THROW(view_page(s.frame, {{"label", {1, 2, 3}}}, s.report), InputError);
  const fs::path dir = fs::path(PROXSEG_TEST_TMP) / "view_page";
  fs::create_directories(dir);
  EXPECT_THROW(view_page_of((dir / "missing").string()), InputError);
  std::ofstream(dir / "other.json") << "[1, 2]";
  EXPECT_THROW(view_page_of((dir / "other").string()), InputError);
  EXPECT_THROW(batch_page(dir.string()), InputError);  // no summary log
}

}  // namespace
