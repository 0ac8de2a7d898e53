// The model database file (recognition/database_io.hpp, docs/database.md): round trip, reading
// only what is used, damaged records confined to their view, planted links and special files,
// writers and readers at once, remove / rename, and the upgrade of version-1 folder databases.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>
#include <proxseg/core/database.hpp>
#include <proxseg/core/errors.hpp>
#include <proxseg/core/render.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/params.hpp>
#include <proxseg/recognition/database_io.hpp>
#include <proxseg/recognition/model_view.hpp>
#include <proxseg/recognition/recognition.hpp>
#include <proxseg/recognition/registration.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <thread>

#include "recognition/folder_database.hpp"
#include "support/folder_database_v1.hpp"

#include "support/fresh_dir.hpp"
#include "support/model_views.hpp"

namespace fs = std::filesystem;
using namespace proxseg;
using namespace proxseg::test;

namespace {

std::vector<RenderedView> rendered(const std::string& id, int views) {
  ViewSphereParams p;
  p.views = views;
  return render_views(read_mesh(kData + "/lmo/models/obj_0000" + id + ".ply", 0.001), p);
}

const std::map<std::string, std::string> kLinemod = {
    {"01", "ape"}, {"05", "can"}, {"06", "cat"}, {"09", "duck"}};

// A database of four LINEMOD objects, `views` rendered views each.
void add_linemod(Database& db, int views) {
  for (const auto& [id, name] : kLinemod)
    for (const auto& v : rendered(id, views)) add_view(db, name, v.points, v.eye, "render");
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The offset in the database file of the floats of `values` (a stretch of a view's record),
// npos when not there whole.
std::size_t find_floats(const std::string& file, const std::vector<float>& values) {
  const std::string pattern(reinterpret_cast<const char*>(values.data()),
                            values.size() * sizeof(float));
  return file.find(pattern);
}

// Changes the database file in place (no connection is open: the WAL is folded in at close).
void overwrite(const std::string& path, std::size_t at, const std::string& bytes) {
  std::fstream f(path, std::ios::binary | std::ios::in | std::ios::out);
  f.seekp(static_cast<std::streamoff>(at));
  f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// Two views equal to the bit: what opening reads and what a recognition reads of them.
void expect_same_view(const ModelView& a, const ModelView& b) {
  EXPECT_EQ(a.object, b.object);
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.source, b.source);
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.coloured, b.coloured);
  EXPECT_EQ(a.viewpoint.allFinite(), b.viewpoint.allFinite());
  if (a.viewpoint.allFinite()) {
    EXPECT_EQ(a.viewpoint, b.viewpoint);
  }
  EXPECT_EQ(a.signature.shape, b.signature.shape);
  EXPECT_EQ(a.signature.colour, b.signature.colour);
  EXPECT_EQ(a.part_sketches.bins, b.part_sketches.bins);
  EXPECT_EQ(a.part_sketches.spreads, b.part_sketches.spreads);
  EXPECT_EQ(a.cloud().points, b.cloud().points);
  EXPECT_EQ(a.cloud().normals, b.cloud().normals);
  EXPECT_EQ(a.cloud().features, b.cloud().features);
  EXPECT_EQ(a.cloud().colours, b.cloud().colours);
  ASSERT_EQ(a.part_signatures().size(), 24u);
  ASSERT_EQ(b.part_signatures().size(), 24u);
  EXPECT_EQ(a.part_signatures()[7].shape, b.part_signatures()[7].shape);
}

TEST(Database, ViewsRoundTripExactly) {
  const std::string dir = fresh_dir("db_roundtrip");
  Database db = open_database(dir, DescriptorParams{});
  const ModelView& milk =
      add_view(db, "milk", read_pcd(kData + "/pcl/milk.pcd"), Eigen::Vector3d::Zero(), "milk.pcd");
  EXPECT_EQ(milk.name, "milk-000");
  EXPECT_GT(milk.points, 1000u);  // 12,575 points filtered at 5 mm
  // milk.pcd is painted (0, 0, 255) throughout: a placeholder, not a colour.
  EXPECT_FALSE(milk.coloured);
  const auto duck = rendered("09", 2).front();
  add_view(db, "duck", duck.points, duck.eye, "duck");
  Frame xyz_only = duck.points;
  xyz_only.rgb.clear();
  add_view(db, "duck shape", xyz_only, duck.eye, "duck without colour");

  const Database again = load_database(dir);
  ASSERT_EQ(again.views.size(), 3u);
  EXPECT_EQ(again.objects(), (std::vector<std::string>{"milk", "duck", "duck shape"}));
  for (std::size_t i = 0; i < 3; ++i) {
    // What add_view() keeps is what a load reads: the same answers in and after the process.
    expect_same_view(db.views[i], again.views[i]);
  }
  EXPECT_EQ(again.views[1].cloud().colours.size(), again.views[1].points);
  EXPECT_TRUE(again.views[2].cloud().colours.empty());
  EXPECT_EQ(again.views[2].signature.colour.size(), 0);
  // A database that is not there, or a name that is not allowed.
  EXPECT_THROW(load_database(fresh_dir("db_none")), FileError);
  EXPECT_THROW(load_database(dir + "/nope"), FileError);
  EXPECT_THROW(add_view(db, "unknown", duck.points, duck.eye, "x"), InputError);
}

// Opening reads the summaries alone; a view's parts and body are read when asked for, once.
TEST(Database, OpeningReadsOnlyTheSummaries) {
  const std::string dir = fresh_dir("db_lazy");
  {
    Database db = open_database(dir, DescriptorParams{});
    add_linemod(db, 2);
  }
  const Database db = load_database(dir);
  ASSERT_EQ(db.views.size(), 8u);
  for (const ModelView& v : db.views) {
    EXPECT_FALSE(v.described->made());
    EXPECT_FALSE(v.parts->made());
  }
  // A shortlist of 2 reads the parts of only the views that can still enter it, and a
  // recognition the bodies of the views it aligns.
  const auto duck = rendered("09", 3).back();
  std::vector<Eigen::Vector3d> xyz;
  for (const auto& p : duck.points.xyz) xyz.push_back(p.cast<double>());
  const Cloud candidate = describe_candidate(xyz, db, &duck.points.rgb);
  RecognitionParams p;
  p.shortlist = 2;
  p.early_exit = 0;
  const Recognition r = recognize(candidate, db, p);
  EXPECT_EQ(r.name, "duck");
  int bodies = 0;
  for (const ModelView& v : db.views) bodies += v.described->made();
  EXPECT_EQ(bodies, r.views_aligned);
  EXPECT_LT(bodies, 8);
}

// The shortlist skips reading parts by a bound and must stay exactly the ranking of every view
// by view_distance().
TEST(Database, ShortlistEqualsTheFullRanking) {
  const std::string dir = fresh_dir("db_bound");
  {
    Database db = open_database(dir, DescriptorParams{});
    add_linemod(db, 6);
  }
  const Database db = load_database(dir);
  for (const auto& [id, name] : kLinemod)
    for (const auto& v : rendered(id, 5)) {
      std::vector<Eigen::Vector3d> xyz;
      for (std::size_t i = 0; i < v.points.size(); i += 2)
        xyz.push_back(v.points.xyz[i].cast<double>());
      const Cloud c = describe_candidate(xyz, db);
      std::vector<std::pair<double, int>> all;
      for (int k = 0; k < static_cast<int>(db.views.size()); ++k) {
        Signature s = db.views[k].signature;
        s.parts = db.views[k].part_signatures();
        all.emplace_back(view_distance(c.signature, s), k);
      }
      std::sort(all.begin(), all.end());
      for (int n : {1, 4, 10}) {
        const std::vector<int> got = shortlist_views(c, db, n);
        ASSERT_GE(got.size(), static_cast<std::size_t>(n));
        for (int k = 0; k < n; ++k) EXPECT_EQ(got[k], all[k].second) << name << " " << n;
      }
    }
}

// A flipped byte in one view's body and zeroed descriptors in another's: `check` names both,
// opening still works, recognition reports the damaged view it read and answers with the others.
TEST(Database, DamagedRecordsAreReportedAndConfined) {
  const std::string dir = fresh_dir("db_damaged");
  std::vector<std::vector<float>> stretches;  // per damaged view: floats of its body to find
  {
    Database db = open_database(dir, DescriptorParams{});
    add_linemod(db, 6);
    for (int v : {18, 7}) {  // a duck view (flipped byte), a can view (zeroed descriptors)
      const Cloud& c = db.views[v].cloud();
      std::vector<float> f;
      if (v == 18) {
        for (int i = 0; i < 8; ++i)
          for (int k = 0; k < 3; ++k) f.push_back(static_cast<float>(c.points[i][k]));
      } else {
        for (int i = 0; i < 12; ++i) f.push_back(static_cast<float>(c.features(i, 0)));
      }
      stretches.push_back(f);
    }
  }
  const std::string file = dir + "/" + kDatabaseFile;
  ASSERT_FALSE(fs::exists(file + "-wal"));  // folded in when the last connection closed
  const std::string bytes = file_bytes(file);
  const std::size_t flip = find_floats(bytes, stretches[0]);
  const std::size_t zero = find_floats(bytes, stretches[1]);
  ASSERT_NE(flip, std::string::npos);
  ASSERT_NE(zero, std::string::npos);
  overwrite(file, flip + 13, std::string(1, static_cast<char>(bytes[flip + 13] ^ 0x10)));
  overwrite(file, zero, std::string(12 * sizeof(float), '\0'));

  const DatabaseCheck check = check_database(dir);
  EXPECT_EQ(check.views, 24);
  EXPECT_EQ(check.whole, 22);
  ASSERT_EQ(check.damaged.size(), 2u);
  std::string all;
  for (const auto& d : check.damaged) all += d + "\n";
  EXPECT_NE(all.find("duck-000"), std::string::npos) << all;
  EXPECT_NE(all.find("can-001"), std::string::npos) << all;
  EXPECT_NE(all.find("body record damaged: its checksum does not match"), std::string::npos) << all;

  const Database db = load_database(dir);
  ASSERT_EQ(db.views.size(), 24u);
  ASSERT_EQ(db.views[18].name, "duck-000");
  EXPECT_THROW(db.views[18].cloud(), InputError);
  EXPECT_THROW(db.views[18].cloud(), InputError);  // the same error again, not a retry
  // A duck: recognition reads every view (the shortlist holds them all), the damaged one among
  // them, reports it, and names the duck from its other views.
  const auto duck = rendered("09", 6)[1];
  std::vector<Eigen::Vector3d> xyz;
  for (const auto& p : duck.points.xyz) xyz.push_back(p.cast<double>());
  RecognitionParams p;
  p.early_exit = 0;
  const Recognition r = recognize(describe_candidate(xyz, db, &duck.points.rgb), db, p);
  ASSERT_GE(r.damaged.size(), 1u);
  EXPECT_TRUE(std::any_of(r.damaged.begin(), r.damaged.end(), [](const std::string& d) {
    return d.find("duck-000") != std::string::npos;
  }));
  EXPECT_EQ(r.name, "duck");
  EXPECT_NE(r.best.view, 18);
}

// The database reads only its own plain files: a link in place of the file or of its WAL, or a
// FIFO in place of the file, is refused at once with the path and why. The directory itself may
// be a link.
TEST(Database, LinksAndSpecialFilesAreRefused) {
  const std::string dir = fresh_dir("db_planted");
  {
    Database db = open_database(dir, DescriptorParams{});
    add_view(db, "milk", read_pcd(kData + "/pcl/milk.pcd"), Eigen::Vector3d::Zero(), "milk");
  }
  const std::string file = dir + "/" + kDatabaseFile, outside = dir + "-outside.sqlite";
  made_dirs().push_back(outside);
  const auto expect_refused = [&](const std::string& path, const std::string& why) {
    try {
      load_database(dir);
      ADD_FAILURE() << "expected a FileError for " << path;
    } catch (const FileError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(path), std::string::npos) << msg;
      EXPECT_NE(msg.find(why), std::string::npos) << msg;
    }
  };
  fs::rename(file, outside);
  fs::create_symlink(outside, file);
  expect_refused(file, "symbolic link");
  fs::remove(file);
  fs::rename(outside, file);
  fs::create_symlink("/proc/self/environ", file + "-wal");
  expect_refused(file + "-wal", "symbolic link");
  fs::remove(file + "-wal");
  ASSERT_NO_THROW(load_database(dir));
  const std::string link = dir + "-link";
  made_dirs().push_back(link);
  fs::create_directory_symlink(dir, link);
  EXPECT_EQ(load_database(link).views.size(), 1u);
  fs::rename(file, outside);
  ASSERT_EQ(::mkfifo(file.c_str(), 0600), 0);
  expect_refused(file, "not a regular file");
  EXPECT_THROW(open_database(dir, DescriptorParams{}), FileError);  // nor written through
  fs::remove(file);
  fs::rename(outside, file);
  // Not a database at all.
  const std::string junk = fresh_dir("db_junk");
  std::ofstream(junk + "/" + kDatabaseFile) << std::string(5000, 'x');
  EXPECT_THROW(load_database(junk), InputError);
}

// Two writers and four readers at once, each with its own connection: every add lands, each
// reader sees whole databases that only grow, and an add takes no longer than alone plus 1 s.
TEST(Database, WritersAndReadersAtOnce) {
  const std::string dir = fresh_dir("db_shared");
  const auto views = rendered("09", 6);
  {
    Database db = open_database(dir, DescriptorParams{});
    add_view(db, "seed", views[0].points, views[0].eye, "seed");
  }
  double alone = 0;
  {
    Database db = load_database(dir);
    const auto t = std::chrono::steady_clock::now();
    add_view(db, "alone", views[1].points, views[1].eye, "alone");
    alone = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
    remove_object(db, "alone");
  }
  std::atomic<bool> writing{true};
  std::atomic<int> reads{0};
  std::vector<std::string> failures(6);
  std::vector<double> slowest(2, 0.0);
  std::vector<std::thread> threads;
  for (int w = 0; w < 2; ++w)
    threads.emplace_back([&, w] {
      try {
        Database db = load_database(dir);
        for (int i = 0; i < 6; ++i) {
          const auto t = std::chrono::steady_clock::now();
          add_view(db, "writer" + std::to_string(w), views[i].points, views[i].eye, "w");
          slowest[w] =
              std::max(slowest[w],
                       std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count());
        }
      } catch (const std::exception& e) {
        failures[w] = e.what();
      }
    });
  for (int r = 0; r < 4; ++r)
    threads.emplace_back([&, r] {
      try {
        std::size_t seen = 0;
        do {
          const Database db = load_database(dir);
          if (db.views.size() < seen) throw std::runtime_error("the database shrank");
          seen = db.views.size();
          if (!db.damaged.empty()) throw std::runtime_error(db.damaged[0]);
          for (const ModelView& v : db.views)  // every view listed is whole
            if (v.cloud().size() != v.points) throw std::runtime_error("a torn view");
          ++reads;
        } while (writing);
      } catch (const std::exception& e) {
        failures[2 + r] = e.what();
      }
    });
  threads[0].join();
  threads[1].join();
  writing = false;
  for (std::size_t t = 2; t < threads.size(); ++t) threads[t].join();
  for (const auto& f : failures) EXPECT_EQ(f, "");
  EXPECT_GE(reads.load(), 4);
  const Database db = load_database(dir);
  EXPECT_EQ(db.views.size(), 13u);
  std::vector<std::string> names;
  for (const ModelView& v : db.views) names.push_back(v.name);
  std::sort(names.begin(), names.end());
  EXPECT_EQ(std::unique(names.begin(), names.end()), names.end());
  for (double s : slowest) EXPECT_LT(s, alone * 3 + 1.0) << "alone " << alone << " s";
  EXPECT_TRUE(check_database(dir).damaged.empty());
}

TEST(Database, RemoveAndRename) {
  const std::string dir = fresh_dir("db_edit");
  Database db = open_database(dir, DescriptorParams{});
  add_linemod(db, 2);
  EXPECT_EQ(remove_object(db, "cat"), 2);
  EXPECT_EQ(rename_object(db, "ape", "monkey"), 2);
  EXPECT_EQ(rename_object(db, "can", "duck"), 2);  // into an existing object: its views join
  EXPECT_THROW(remove_object(db, "cat"), InputError);
  EXPECT_THROW(rename_object(db, "duck", ""), InputError);
  const Database again = load_database(dir);
  EXPECT_EQ(again.objects(), (std::vector<std::string>{"monkey", "duck"}));
  EXPECT_EQ(again.views.size(), 6u);
  EXPECT_EQ(db.objects(), again.objects());
  // A view added after a remove never reuses a removed record.
  add_view(db, "cat", read_pcd(kData + "/pcl/milk.pcd"), Eigen::Vector3d::Zero(), "milk");
  EXPECT_GT(db.views.back().record, 8);
  const nlohmann::json info = database_info(load_database(dir));
  EXPECT_EQ(info["views"], 7);
  EXPECT_GT(info["file_bytes"].get<std::size_t>(), info["record_bytes"].get<std::size_t>() / 2);
  EXPECT_GT(info["objects"][0]["bytes"].get<std::size_t>(), 50000u);
  EXPECT_TRUE(check_database(dir).damaged.empty());
}

// `db upgrade` keeps every view bit for bit, so recognition answers as before.
TEST(Database, UpgradedFolderDatabasesGiveTheSameAnswers) {
  const std::string dir = fresh_dir("db_v1");
  {
    Database made;
    made.dir = fresh_dir("db_v1_source");
    add_linemod(made, 3);
    Frame xyz_only = rendered("05", 2)[1].points;
    xyz_only.rgb.clear();
    add_view(made, "can shape", xyz_only, Eigen::Vector3d::Constant(std::nan("")), "xyz");
    test::write_folder_database(dir, made.views, made.descriptor);
  }
  try {
    load_database(dir);
    FAIL() << "a version-1 database opened without an upgrade";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("proxseg db upgrade"), std::string::npos) << e.what();
  }
  // A link planted for a view is refused, not followed (the version-1 checks stay).
  const std::string pcd = dir + "/views/ape-000.pcd", kept = dir + "-ape.pcd";
  made_dirs().push_back(kept);
  fs::rename(pcd, kept);
  fs::create_symlink(kept, pcd);
  try {
    upgrade_database(dir);
    ADD_FAILURE() << "a link planted for a view was followed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("symbolic link"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir + "/" + kDatabaseFile));
  fs::remove(pcd);
  fs::rename(kept, pcd);
  const Database old = detail::read_folder_database(dir);
  EXPECT_EQ(upgrade_database(dir), 13);
  EXPECT_THROW(upgrade_database(dir), InputError);  // once
  const Database db = load_database(dir);
  ASSERT_EQ(db.views.size(), old.views.size());
  for (std::size_t i = 0; i < db.views.size(); ++i) {
    expect_same_view(old.views[i], db.views[i]);
  }
  RecognitionParams p;
  for (const auto& [id, name] : kLinemod) {
    const Frame seen = rendered(id, 5)[2].points;
    const SceneObject x = recognize_object(seen, old, p), y = recognize_object(seen, db, p);
    EXPECT_EQ(x.recognition.name, y.recognition.name);
    EXPECT_EQ(x.recognition.best.view, y.recognition.best.view);
    EXPECT_EQ(x.recognition.best.score, y.recognition.best.score);
    EXPECT_EQ(x.recognition.best.pose, y.recognition.best.pose);
  }
}

}  // namespace
