// `proxseg view PREFIX`: the 3D page of a result (io/view_page.hpp), PREFIX.html beside its
// files; `proxseg view OUT/`: the page of a batch folder (io/batch_page.hpp), OUT/index.html;
// -o - writes the page to stdout.
#include <proxseg/io/batch_page.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/view_page.hpp>

#include <filesystem>
#include <iostream>

#include "cli.hpp"

namespace cli {

namespace {
constexpr const char* kPage = "Page";
}  // namespace

void add_view(CLI::App& app, ViewCommandOptions& o) {
  auto* cmd = app.add_subcommand(
      "view",
      "Write the 3D page of a result (PREFIX.html) or the page of a batch (OUT/index.html): "
      "one file that any browser opens");
  cmd->add_option("prefix", o.prefix,
                  "A result's prefix, as segment or recognize -o named it (PREFIX.json and "
                  "PREFIX.pcd), or a batch's folder")
      ->required();
  cmd->add_option("-o,--output", o.output,
                  "The page's file (default PREFIX.html, or OUT/index.html for a batch); - for "
                  "stdout")
      ->group(group::kOutput);
  cmd->add_option("--max-points", o.max_points,
                  "Show every k-th point of larger clouds (the page says so); 0 = all")
      ->capture_default_str()
      ->group(kPage);
  cmd->add_option("--title", o.title, "The page's title (default the prefix's name)")->group(kPage);
  help_last(cmd);
}

namespace {

int write_page(const std::string& path, const std::string& page) {
  if (path == "-") {
    std::cout << page;
    return 0;
  }
  make_parent(path);
  proxseg::write_file_atomic(path, page);
  say() << path << ": " << page.size() / 1024 << " KiB\n";
  return 0;
}

}  // namespace

int run_view(const ViewCommandOptions& o) {
  std::string prefix = o.prefix;
  if (prefix.size() > 5 && prefix.compare(prefix.size() - 5, 5, ".json") == 0)
    prefix.resize(prefix.size() - 5);  // the report named instead of the prefix
  if (std::filesystem::is_directory(prefix))
    return write_page(
        o.output.empty() ? (std::filesystem::path(prefix) / "index.html").string() : o.output,
        proxseg::batch_page(prefix, o.title));
  proxseg::ViewOptions options;
  options.max_points = o.max_points;
  options.title = o.title;
  return write_page(o.output.empty() ? prefix + ".html" : o.output,
                    proxseg::view_page_of(prefix, options));
}

}  // namespace cli
