// SPDX-License-Identifier: MIT
#include "cli_options.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <limits>

namespace sph_tools {

const char* usage_text() {
  return "usage: sph-run SCENE.json [options]\n"
         "\n"
         "Runs a scene file (docs/scenes.md) and writes its frames (docs/cli.md).\n"
         "\n"
         "options:\n"
         "  --frames N          frames to simulate (default: the scene's time.frames)\n"
         "  --backend B         auto | cpu | cuda (default auto: CUDA when a GPU is present)\n"
         "  --out DIR           output directory (default: the scene's output.directory,\n"
         "                      else out/<scene file name>)\n"
         "  --format F          vdb | ply | csv | vtp | none; several as vdb,vtp (default: the scene's,\n"
         "                      else vdb; ply in builds without OpenVDB)\n"
         "  --surface           also write the fluid surface: level set (.vdb) and mesh (.obj)\n"
         "  --preview           draw every frame to PNG, and an MP4 when ffmpeg is on PATH\n"
         "  --preview-style S   particles | surface (implies --preview; surface needs --surface)\n"
         "  --threads N         CPU backend threads (default: all)\n"
         "  --dfsph-lists       CUDA DFSPH: neighbour lists for the solves (256 B a particle more,\n"
         "                      faster solves; docs/cuda.md)\n"
         "  --quiet             no progress, only warnings, errors and the summary\n"
         "  --stats-json FILE   also write the summary's figures to FILE as JSON (benchmarks)\n"
         "  --version           print the library's build information\n"
         "  -h, --help          this text\n"
         "\n"
         "exit codes: 0 ok, 1 runtime error, 2 usage error, 3 scene file error,\n"
         "            4 backend unavailable, 5 output unavailable in this build,\n"
         "            130 interrupted (only complete frames are kept)\n";
}

namespace {

const char* const kOptions[] = {"--frames",  "--backend",       "--out",        "--format", "--surface",
                                "--preview", "--preview-style", "--threads",    "--quiet",  "--stats-json",
                                "--version", "--help",          "--dfsph-lists"};

// Levenshtein distance: the number of single-character edits between a and b.
size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// "unknown option --frame (did you mean --frames?)": the closest option within a third of its
// length (at least two edits), so a typo is named and a wholly foreign word is not matched.
std::string unknown_option_message(const std::string& arg) {
  std::string best;
  size_t best_distance = std::numeric_limits<size_t>::max();
  const std::string dashed = arg.rfind("--", 0) == 0 ? arg : "-" + arg;
  for (const char* option : kOptions) {
    const size_t d = edit_distance(dashed, option);
    if (d < best_distance) {
      best_distance = d;
      best = option;
    }
  }
  std::string message = "unknown option " + arg;
  if (best_distance <= std::max<size_t>(2, best.size() / 3)) message += " (did you mean " + best + "?)";
  return message;
}

uint32_t parse_count(const std::string& option, const char* text, uint32_t lo, uint32_t hi) {
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(text, &end, 10);
  if (!text[0] || *end || errno || v < lo || v > hi)
    throw UsageError(option + ": expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                     "], got \"" + text + "\"");
  return static_cast<uint32_t>(v);
}

std::vector<OutputFormat> parse_formats(const char* text) {
  std::vector<OutputFormat> formats;
  const std::string all = text;
  if (all == "none") return formats;
  size_t start = 0;
  while (true) {
    const size_t comma = all.find(',', start);
    const std::string f = all.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (f == "vdb")
      formats.push_back(OutputFormat::kVdb);
    else if (f == "ply")
      formats.push_back(OutputFormat::kPly);
    else if (f == "csv")
      formats.push_back(OutputFormat::kCsv);
    else if (f == "vtp")
      formats.push_back(OutputFormat::kVtp);
    else
      throw UsageError("--format: expected vdb, ply, csv, vtp or none (several as vtp,ply), got \"" + all +
                       "\"");
    for (size_t k = 0; k + 1 < formats.size(); ++k)
      if (formats[k] == formats.back())
        throw UsageError("--format: \"" + f + "\" is given twice in \"" + all + "\"");
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return formats;
}

}  // namespace

CliOptions parse_cli(int argc, char** argv) {
  CliOptions o;
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    std::string value;
    bool has_inline_value = false;
    if (arg.rfind("--", 0) == 0) {
      const size_t eq = arg.find('=');
      if (eq != std::string::npos) {
        value = arg.substr(eq + 1);
        arg = arg.substr(0, eq);
        has_inline_value = true;
      }
    }
    auto next = [&]() -> const char* {
      if (has_inline_value) return value.c_str();
      if (i + 1 >= argc) throw UsageError(arg + ": missing its value");
      return argv[++i];
    };
    auto no_value = [&] {
      if (has_inline_value) throw UsageError(arg + ": takes no value");
    };
    if (arg == "-h" || arg == "--help") {
      no_value();
      o.help = true;
    } else if (arg == "--version") {
      no_value();
      o.version = true;
    } else if (arg == "--frames") {
      o.frames = parse_count(arg, next(), 0, 10000000);
    } else if (arg == "--backend") {
      const std::string b = next();
      if (b == "auto")
        o.backend = SPH_BACKEND_AUTO;
      else if (b == "cpu")
        o.backend = SPH_BACKEND_CPU;
      else if (b == "cuda")
        o.backend = SPH_BACKEND_CUDA;
      else
        throw UsageError("--backend: expected auto, cpu or cuda, got \"" + b + "\"");
    } else if (arg == "--out") {
      o.out = next();
      if (o.out->empty()) throw UsageError("--out: expected a directory");
    } else if (arg == "--format") {
      o.formats = parse_formats(next());
    } else if (arg == "--surface") {
      no_value();
      o.surface = true;
    } else if (arg == "--preview") {
      no_value();
      o.preview = true;
    } else if (arg == "--preview-style") {
      const std::string style = next();
      if (style != "particles" && style != "surface")
        throw UsageError("--preview-style: expected particles or surface, got \"" + style + "\"");
      o.preview = true;
      o.preview_surface = style == "surface";
    } else if (arg == "--threads") {
      o.threads = parse_count(arg, next(), 1, 4096);
    } else if (arg == "--quiet") {
      no_value();
      o.quiet = true;
    } else if (arg == "--dfsph-lists") {
      no_value();
      o.dfsph_lists = true;
    } else if (arg == "--stats-json") {
      o.stats_json = next();
      if (o.stats_json->empty()) throw UsageError("--stats-json: expected a file name");
    } else if (arg.size() > 1 && arg[0] == '-') {
      throw UsageError(unknown_option_message(arg));
    } else if (o.scene.empty()) {
      o.scene = arg;
    } else {
      throw UsageError("one scene file only; got \"" + o.scene + "\" and \"" + arg + "\"");
    }
  }
  if (o.scene.empty() && !o.help && !o.version) throw UsageError("missing the scene file");
  return o;
}

}  // namespace sph_tools
