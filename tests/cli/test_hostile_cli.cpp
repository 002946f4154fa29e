// SPDX-License-Identifier: MIT
// sph-run under hostile conditions (issue 23, items 3, 5 and 8): links planted in the output
// directory, other programs' files there, kills at any moment, frames of an earlier run,
// special files as input, an unwritable --stats-json, a file size limit, and scene values that
// only fail at run time. Part of the hostile-input suite (ctest label `hostile`).
//   usage: cli_hostile SPH_RUN SCENES_DIR
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <set>
#include <string>
#include <thread>

extern "C" {
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
}

#include "cli_test_support.h"

namespace {

std::string g_sph_run, g_scenes;

int run(const std::vector<std::string>& args, std::string* output, int timeout_s = 120) {
  std::vector<std::string> argv = {g_sph_run};
  argv.insert(argv.end(), args.begin(), args.end());
  const int status = cli_test::run(argv, output, timeout_s);
  std::printf("$ sph-run");
  for (const std::string& a : args) std::printf(" %s", a.c_str());
  std::printf("  -> %d\n%s", status, output->c_str());
  return status;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::vector<std::string> tiny(const std::string& out, const char* frames, const char* formats = "ply,csv") {
  return {g_scenes + "/tiny.json",
          "--frames",
          frames,
          "--backend",
          "cpu",
          "--format",
          formats,
          "--out",
          out,
          "--threads",
          "1",
          "--quiet"};
}

bool is_link(const std::string& path) {
  struct stat st;
  return lstat(path.c_str(), &st) == 0 && S_ISLNK(st.st_mode);
}

// The frames the manifest calls complete, with their files.
struct Manifest {
  std::vector<std::pair<unsigned, std::vector<std::string>>> complete;
  std::string end;  // the "end" line, or "" if the run did not write one
};

std::vector<std::string> string_list(const std::string& line, const char* key) {
  std::vector<std::string> out;
  size_t at = line.find(std::string("\"") + key + "\":[");
  if (at == std::string::npos) return out;
  at = line.find('[', at) + 1;
  const size_t close = line.find(']', at);
  while (at < close) {
    const size_t open = line.find('"', at);
    if (open == std::string::npos || open > close) break;
    const size_t end = line.find('"', open + 1);
    out.push_back(line.substr(open + 1, end - open - 1));
    at = end + 1;
  }
  return out;
}

Manifest read_manifest(const std::string& dir) {
  Manifest m;
  const std::string text = cli_test::read_text(dir + "/sph-run-manifest.jsonl");
  for (size_t at = 0, end; (end = text.find('\n', at)) != std::string::npos; at = end + 1) {
    const std::string line = text.substr(at, end - at);
    unsigned frame = 0;
    if (std::sscanf(line.c_str(), "{\"frame\":%u,", &frame) == 1 && contains(line, "\"state\":\"complete\""))
      m.complete.emplace_back(frame, string_list(line, "files"));
    if (line.compare(0, 7, "{\"end\":") == 0) m.end = line;
  }
  return m;
}

// Every frame the manifest calls complete has every file it lists, whole.
void expect_complete_frames_whole(const std::string& dir, const Manifest& m) {
  for (const auto& frame : m.complete) {
    assert_int_equal(frame.second.size(), 2);  // ply and csv
    cli_test::Particles ply, csv;
    std::string error;
    const std::string ply_path = dir + "/" + frame.second[0], csv_path = dir + "/" + frame.second[1];
    if (!cli_test::read_ply(ply_path, &ply, &error)) std::printf("%s: %s\n", ply_path.c_str(), error.c_str());
    assert_true(cli_test::read_ply(ply_path, &ply, &error));
    assert_true(cli_test::read_csv(csv_path, &csv, &error));
    assert_int_equal(ply.count(), csv.count());
    assert_true(ply.id == csv.id);
  }
}

// ---- item 3: links planted in the output directory are not followed -------------------------
void test_planted_links_are_not_followed(void**) {
  const std::string dir = cli_test::make_temp_dir("links");
  const std::string victim = dir + "/victim.txt", out = dir + "/out";
  cli_test::write_text(victim, "precious\n");
  mkdir(out.c_str(), 0755);
  // The temporary name an earlier sph-run used, the final names, the manifest, and a staging
  // directory name: each a link to the victim.
  for (const char* name : {".fluid_0000.ply.tmp", ".fluid_0001.csv.tmp", "fluid_0000.ply", "fluid_0001.csv",
                           "sph-run-manifest.jsonl", ".sph-run-AAAAAA"})
    assert_int_equal(symlink(victim.c_str(), (out + "/" + name).c_str()), 0);
  std::string output;
  assert_int_equal(run(tiny(out, "1"), &output), 0);
  assert_string_equal(cli_test::read_text(victim).c_str(), "precious\n");
  // The outputs replaced the links (rename(2) replaces a link, it does not write through it).
  for (const char* name : {"fluid_0000.ply", "fluid_0001.csv", "sph-run-manifest.jsonl"})
    assert_false(is_link(out + "/" + name));
  // Links that are not sph-run's files stay as they were.
  assert_true(is_link(out + "/.fluid_0000.ply.tmp") && is_link(out + "/.sph-run-AAAAAA"));
  expect_complete_frames_whole(out, read_manifest(out));
}

// ---- item 3: other programs' hidden files survive the start-up clean-up ----------------------
void test_foreign_files_survive(void**) {
  const std::string out = cli_test::make_temp_dir("foreign");
  cli_test::write_text(out + "/.notes.tmp", "mine\n");
  mkdir((out + "/.cache.tmp").c_str(), 0755);       // an empty directory of another program
  mkdir((out + "/.sph-run-Foreig").c_str(), 0755);  // a staging-like name holding a user file
  cli_test::write_text(out + "/.sph-run-Foreig/keep.txt", "x");
  cli_test::write_text(out + "/.sph-run-plainf", "a file, not a directory");
  cli_test::write_text(out + "/fluid_0099.ply", "a file no manifest recorded");
  cli_test::write_text(out + "/notes.txt", "mine\n");
  // What a killed run left: a staging directory with a frame file in it (its lock died with
  // it), and an earlier version's hidden temporary.
  mkdir((out + "/.sph-run-Killed").c_str(), 0700);
  cli_test::write_text(out + "/.sph-run-Killed/fluid_0003.ply", "partial");
  cli_test::write_text(out + "/.fluid_0002.csv.tmp", "partial");
  std::string output;
  assert_int_equal(run(tiny(out, "1"), &output), 0);
  for (const char* kept : {".notes.tmp", ".cache.tmp", ".sph-run-Foreig/keep.txt", ".sph-run-plainf",
                           "fluid_0099.ply", "notes.txt"})
    assert_true(cli_test::file_exists(out + "/" + kept));
  assert_false(cli_test::file_exists(out + "/.sph-run-Killed"));
  assert_false(cli_test::file_exists(out + "/.fluid_0002.csv.tmp"));
  // Nothing of this run's staging is left.
  for (const std::string& name : cli_test::list_dir(out))
    assert_true(name.compare(0, 9, ".sph-run-") != 0 || name == ".sph-run-Foreig" ||
                name == ".sph-run-plainf");
}

// ---- item 3: a frame is all or nothing, whenever the run is killed --------------------------
void test_killed_runs_leave_whole_frames(void**) {
  const std::string out = cli_test::make_temp_dir("killed");
  size_t trusted = 0;
  const std::string manifest = out + "/sph-run-manifest.jsonl";
  for (int trial = 0; trial < 8; ++trial) {
    struct stat before;
    const ino_t last_inode = stat(manifest.c_str(), &before) == 0 ? before.st_ino : 0;
    const pid_t pid =
        cli_test::start({g_sph_run, g_scenes + "/tiny.json", "--frames", "100000", "--backend", "cpu",
                         "--format", "ply,csv", "--out", out, "--threads", "1", "--quiet"},
                        out + ".log");
    // Kills at different moments of a frame: start-up, writing, moving files, the manifest.
    // The first two trials kill at fixed times (start-up on a slow machine); the others wait
    // for this run's first complete frame (its manifest replaced the last run's: a new inode),
    // so that a loaded machine or a sanitizer build still kills mid-run, never only at start-up.
    if (trial >= 2) {
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
      while (std::chrono::steady_clock::now() < deadline) {
        struct stat now;
        if (stat(manifest.c_str(), &now) == 0 && now.st_ino != last_inode &&
            !read_manifest(out).complete.empty())
          break;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(150 + 37 * trial));
    kill(pid, SIGKILL);
    assert_int_equal(cli_test::wait_for(pid, 60), 128 + SIGKILL);
    const Manifest m = read_manifest(out);
    assert_true(m.end.empty());
    expect_complete_frames_whole(out, m);
    for (size_t k = 0; k < m.complete.size(); ++k) assert_int_equal(m.complete[k].first, k);
    trusted += m.complete.size();
  }
  std::printf("8 killed runs: %zu complete frames, all whole\n", trusted);
  assert_true(trusted > 0);
  // The next run cleans up every killed run's staging directory, and the frames the last one
  // recorded: only this run's frames are left.
  std::string output;
  assert_int_equal(run(tiny(out, "1"), &output), 0);
  std::vector<std::string> names = cli_test::list_dir(out);
  std::sort(names.begin(), names.end());
  const std::vector<std::string> expected = {"fluid_0000.csv", "fluid_0000.ply", "fluid_0001.csv",
                                             "fluid_0001.ply", "sph-run-manifest.jsonl"};
  for (const std::string& n : names) std::printf("  %s\n", n.c_str());
  assert_true(names == expected);
  assert_true(contains(read_manifest(out).end, "\"end\":\"complete\""));
}

// ---- item 3: frames of an earlier, longer run do not linger --------------------------------
void test_earlier_longer_run_is_replaced(void**) {
  const std::string out = cli_test::make_temp_dir("longer");
  std::string output;
  assert_int_equal(run(tiny(out, "5", "ply"), &output), 0);
  assert_true(cli_test::file_exists(out + "/fluid_0005.ply"));
  assert_int_equal(run(tiny(out, "2", "csv"), &output), 0);
  std::vector<std::string> names = cli_test::list_dir(out);
  std::sort(names.begin(), names.end());
  const std::vector<std::string> expected = {"fluid_0000.csv", "fluid_0001.csv", "fluid_0002.csv",
                                             "sph-run-manifest.jsonl"};
  assert_true(names == expected);
}

// The loads' and probes' tables of an earlier run go like its frames (they lingered: the manifest
// did not record them, so a run without the probes left the old files beside the new frames); a
// file of the same pattern that no manifest recorded stays; an object's name longer than a file
// name may be goes into its table's name cut at 200 characters (it failed the run, "File name too
// long", after the first frame).
void test_earlier_run_tables_are_replaced(void**) {
  const std::string dir = cli_test::make_temp_dir("tables");
  const std::string out = dir + "/out";
  const std::string scene = dir + "/tables.json";
  const std::string long_name(300, 'n');
  cli_test::write_text(scene, R"({
    "world": { "capacity": 4000, "particle_spacing": 0.02 },
    "time": { "fps": 50, "frames": 2 },
    "fluids": [ { "type": "box", "min": [-0.1, 0.0, -0.1], "max": [0.1, 0.06, 0.1] } ],
    "colliders": [ { "name": "tank", "inverted": true, "loads": {},
                     "shape": { "type": "box", "half_extents": [0.1, 0.1, 0.1], "voxel_size": 0.02 },
                     "transform": { "position": [0, 0.1, 0] } } ],
    "probes": [ { "type": "point", "position": [0, 0.02, 0] },
                { "type": "point", "name": ")" +
                                  long_name + R"(", "position": [0, 0.04, 0] } ] })");
  std::string output;
  assert_int_equal(
      run({scene, "--backend", "cpu", "--threads", "1", "--format", "csv", "--out", out, "--quiet"}, &output),
      0);
  const std::string cut = "probe_1_" + std::string(200, 'n') + ".csv";
  for (const std::string& name : {std::string("loads_0_tank.csv"), std::string("probe_0.csv"), cut})
    assert_true(cli_test::file_exists(out + "/" + name));
  cli_test::write_text(out + "/probe_7_mine.csv", "a file no manifest recorded");
  assert_int_equal(run(tiny(out, "1", "csv"), &output), 0);
  std::vector<std::string> names = cli_test::list_dir(out);
  std::sort(names.begin(), names.end());
  const std::vector<std::string> expected = {"fluid_0000.csv", "fluid_0001.csv", "probe_7_mine.csv",
                                             "sph-run-manifest.jsonl"};
  assert_true(names == expected);
}

// A format given twice would write one file twice a frame: refused before anything runs, as a
// usage error on the command line (exit 2) and a scene error in the file (exit 3). It passed both
// checks and failed at the first frame ("File exists", exit 1).
void test_repeated_format_is_refused(void**) {
  const std::string dir = cli_test::make_temp_dir("formats");
  std::string output;
  assert_int_equal(run(tiny(dir + "/out", "1", "csv,ply,csv"), &output), 2);
  assert_true(contains(output, "--format: \"csv\" is given twice in \"csv,ply,csv\""));
  const std::string scene = dir + "/scene.json";
  cli_test::write_text(scene, R"({"output": {"format": ["vtp", "vtp"]}})");
  assert_int_equal(run({scene, "--out", dir + "/out", "--backend", "cpu", "--frames", "0"}, &output), 3);
  assert_true(contains(output, "output.format[1]: expected a format not listed before it"));
  assert_false(cli_test::file_exists(dir + "/out/fluid_0000.vtp"));
}

// ---- item 5: special files as input --------------------------------------------------------
void test_special_input_files_are_scene_errors(void**) {
  const std::string dir = cli_test::make_temp_dir("special");
  std::string output;
  const auto t0 = std::chrono::steady_clock::now();
  assert_int_equal(run({"/dev/zero", "--out", dir + "/out"}, &output, 30), 3);
  assert_true(contains(output, "not a regular file"));
  const std::string fifo = dir + "/scene.json";
  assert_int_equal(mkfifo(fifo.c_str(), 0600), 0);
  assert_int_equal(run({fifo, "--out", dir + "/out"}, &output, 30), 3);  // no writer: must not wait
  assert_true(contains(output, "not a regular file"));
  // Well under the 30 s each was allowed: neither was read nor waited on.
  assert_true(std::chrono::steady_clock::now() - t0 < std::chrono::seconds(20));
#ifndef CLI_TEST_NO_OPENVDB
  // A level-set file that is a FIFO: the loader refuses it by its type, without opening it.
  const std::string scene = dir + "/vdb.json";
  cli_test::write_text(scene, R"({"colliders": [{"shape": {"type": "vdb", "file": "scene.json"}}]})");
  assert_int_equal(run({scene, "--out", dir + "/out", "--backend", "cpu", "--frames", "0"}, &output, 30), 3);
  assert_true(contains(output, "not a regular file"));
#endif
}

// A level-set file cut short (a copy interrupted, a cache still being written): OpenVDB's
// io::File went on past its end with offsets and lengths it had failed to read, and sph-run
// (the preview's bounds, then sph_vdb_load_sdf) allocated gigabytes without end. Now a scene
// error that names the file, at once; so is a file whose delayed-load metadata lies.
void test_truncated_level_set_is_a_scene_error(void**) {
#ifndef CLI_TEST_NO_OPENVDB
  const std::string dir = cli_test::make_temp_dir("cutvdb");
  std::vector<std::string> args = tiny(dir + "/out", "0", "none");
  args.push_back("--surface");
  std::string output;
  assert_int_equal(run(args, &output), 0);
  const std::string whole = cli_test::read_text(dir + "/out/surface_0000.vdb");
  // Cut just after the grid's type name, before its offsets.
  const size_t at = whole.find("Tree_float_5_4_3");
  assert_true(at != std::string::npos);
  cli_test::write_text(dir + "/cut.vdb", whole.substr(0, at + 16));
  const std::string scene = dir + "/cut.json";
  cli_test::write_text(scene, R"({"colliders": [{"shape": {"type": "vdb", "file": "cut.vdb"}}]})");
  const auto t0 = std::chrono::steady_clock::now();
  assert_int_equal(run({scene, "--out", dir + "/out2", "--backend", "cpu", "--frames", "0"}, &output, 60), 3);
  assert_true(contains(output, "cut.vdb' as a VDB file: it ends early"));
  assert_true(std::chrono::steady_clock::now() - t0 < std::chrono::seconds(20));
  // fuzz_vdb's delayed-load regression (its selector byte dropped): the preview's bounds read it
  // with io::File's delayed loading, whose mask-table assertion aborted sph-run (status 134).
  const std::string planted =
      cli_test::read_text(g_scenes + "/../../fuzz/regressions/vdb/delayed-load-mask-index-assert.vdb");
  assert_true(planted.size() > 1);
  cli_test::write_text(dir + "/cut.vdb", planted.substr(1));
  assert_int_equal(run({scene, "--out", dir + "/out3", "--backend", "cpu", "--frames", "0"}, &output, 60), 3);
  assert_true(contains(output, "cut.vdb"));
#endif
}

// ---- item 8: --stats-json that cannot be written ------------------------------------------
void test_unwritable_stats_json_fails(void**) {
  const std::string out = cli_test::make_temp_dir("stats");
  std::vector<std::string> args = tiny(out, "1");
  args.push_back("--stats-json");
  args.push_back(out + "/no/such/dir/stats.json");
  std::string output;
  assert_int_equal(run(args, &output), 1);
  assert_true(
      contains(output, "--stats-json: cannot write " + out + "/no/such/dir/stats.json: No such file"));
}

// ---- item 8: a file size limit is an error, not a kill ------------------------------------
void test_file_size_limit_is_an_error(void**) {
  const std::string out = cli_test::make_temp_dir("fsize");
  // 8 KiB of file (ulimit -f counts 1024-byte blocks in bash): a frame of the tiny scene is
  // 13 KB of PLY. Without sph-run ignoring SIGXFSZ the kernel would kill it (status 153).
  std::string command = "ulimit -f 8 && exec '" + g_sph_run + "'";
  for (const std::string& a : tiny(out, "1")) command += " '" + a + "'";
  std::string output;
  const int status = cli_test::run({"/bin/bash", "-c", command}, &output);
  std::printf("%s-> %d\n", output.c_str(), status);
  assert_int_equal(status, 1);
  assert_true(contains(output, "File too large"));
  // Nothing of the frame was committed.
  assert_false(cli_test::file_exists(out + "/fluid_0000.ply"));
#ifndef CLI_TEST_NO_OPENVDB
  // OpenVDB's own io::File::write never checked its stream: the truncated .vdb was committed
  // as a whole frame, and the run exited 0.
  command = "ulimit -f 8 && exec '" + g_sph_run + "'";
  for (const std::string& a : tiny(out, "1", "vdb")) command += " '" + a + "'";
  assert_int_equal(cli_test::run({"/bin/bash", "-c", command}, &output), 1);
  std::printf("%s", output.c_str());
  assert_true(contains(output, "fluid_0000.vdb: File too large"));
  assert_false(cli_test::file_exists(out + "/fluid_0000.vdb"));
#endif
}

// ---- item 8: scene values that pass the schema but cannot run -------------------------------
void test_runtime_scene_values_are_scene_errors(void**) {
  const std::string dir = cli_test::make_temp_dir("values");
  const std::string scene = dir + "/scene.json";
  std::string output;
  cli_test::write_text(scene, R"({"time": {"fps": 1e-40, "frames": 1}})");
  assert_int_equal(run({scene, "--out", dir + "/out", "--backend", "cpu"}, &output), 3);
  assert_true(contains(output, "time.fps: expected a frame rate in [0.001, 100000]"));
#ifndef CLI_TEST_NO_OPENVDB
  cli_test::write_text(scene, R"({"output": {"surface": {"voxel_size": 1e-5}}})");
  assert_int_equal(run({scene, "--out", dir + "/out", "--backend", "cpu", "--frames", "0"}, &output), 3);
  assert_true(contains(output, "output.surface.voxel_size: expected at least 1/16 of the particle radius"));
#endif
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s SPH_RUN SCENES_DIR\n", argv[0]);
    return 2;
  }
  g_sph_run = argv[1];
  g_scenes = argv[2];
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_planted_links_are_not_followed),
      cmocka_unit_test(test_foreign_files_survive),
      cmocka_unit_test(test_killed_runs_leave_whole_frames),
      cmocka_unit_test(test_earlier_longer_run_is_replaced),
      cmocka_unit_test(test_earlier_run_tables_are_replaced),
      cmocka_unit_test(test_repeated_format_is_refused),
      cmocka_unit_test(test_special_input_files_are_scene_errors),
      cmocka_unit_test(test_truncated_level_set_is_a_scene_error),
      cmocka_unit_test(test_unwritable_stats_json_fails),
      cmocka_unit_test(test_file_size_limit_is_an_error),
      cmocka_unit_test(test_runtime_scene_values_are_scene_errors),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
