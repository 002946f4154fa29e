// SPDX-License-Identifier: MIT
// sph-run's exit codes (issue 7, items 2 and 6): usage errors, scene-file errors, backends that
// are not there, and an interrupted run that keeps only complete frames.
//   usage: cli_exit_codes SPH_RUN SCENES_DIR
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
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
#include "sph_c.h"

namespace {

std::string g_sph_run, g_scenes;

int run(const std::vector<std::string>& args, std::string* output) {
  std::vector<std::string> argv = {g_sph_run};
  argv.insert(argv.end(), args.begin(), args.end());
  const int status = cli_test::run(argv, output);
  std::printf("$ sph-run");
  for (const std::string& a : args) std::printf(" %s", a.c_str());
  std::printf("  -> %d\n%s", status, output->c_str());
  return status;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

void test_usage_errors_exit_2(void**) {
  std::string out;
  assert_int_equal(run({}, &out), 2);
  // One line naming the problem and a pointer to --help, not the whole usage again.
  assert_true(contains(out, "missing the scene file") && contains(out, "sph-run --help") &&
              !contains(out, "usage: sph-run"));
  assert_int_equal(run({"--help"}, &out), 0);
  assert_true(contains(out, "exit codes"));
  const std::string scene = g_scenes + "/tiny.json";
  assert_int_equal(run({scene, "--bogus"}, &out), 2);
  assert_true(contains(out, "unknown option --bogus") && !contains(out, "did you mean"));
  assert_int_equal(run({scene, "--quite"}, &out), 2);
  assert_true(contains(out, "unknown option --quite (did you mean --quiet?)"));
  assert_int_equal(run({scene, "--backend", "gpu"}, &out), 2);
  assert_true(contains(out, "--backend: expected auto, cpu or cuda, got \"gpu\""));
  assert_int_equal(run({scene, "--frames", "-1"}, &out), 2);
  assert_true(contains(out, "--frames: expected an integer"));
  assert_int_equal(run({scene, "--frames"}, &out), 2);
  assert_true(contains(out, "--frames: missing its value"));
  assert_int_equal(run({scene, "--format", "exr"}, &out), 2);
  assert_int_equal(run({scene, "--dfsph-lists=yes"}, &out), 2);  // a switch takes no value
  assert_int_equal(run({scene, scene}, &out), 2);
}

void test_scene_errors_exit_3(void**) {
  std::string out;
  assert_int_equal(run({"/nonexistent/scene.json"}, &out), 3);
  assert_true(contains(out, "cannot open /nonexistent/scene.json"));
  const std::string dir = cli_test::make_temp_dir("bad_scene");
  const std::string bad = dir + "/bad.json";
  cli_test::write_text(bad, R"({"colliders": [{"shape": {"type": "sphere", "radius": -0.5}}]})");
  assert_int_equal(run({bad, "--out", dir + "/out"}, &out), 3);
  assert_true(contains(out, "colliders[0].shape.radius: expected a positive number, got -0.5"));
  cli_test::write_text(bad, R"({"world": {"surface_tension": 0.07}})");
  assert_int_equal(run({bad, "--out", dir + "/out"}, &out), 3);
  assert_true(contains(out, "world.surface_tension: unknown field"));
  cli_test::write_text(bad, "{\"world\": }");
  assert_int_equal(run({bad, "--out", dir + "/out"}, &out), 3);
  assert_true(contains(out, "not valid JSON: parse error at line 1"));
  // A parameter the library refuses: a scene error at the field's path, with its rule.
  cli_test::write_text(
      bad, R"({"world": {"equation_of_state": "tait"}, "physics": {"tait": {"speed_of_sound": -1}}})");
  assert_int_equal(run({bad, "--out", dir + "/out", "--backend", "cpu"}, &out), 3);
  assert_true(contains(out, "physics.tait.speed_of_sound: must be > 0, got -1"));
  // Rejected by the library while building: still a scene error, at the object's path.
  cli_test::write_text(
      bad,
      R"({"world": {"capacity": 10}, "fluids": [{"type": "sphere", "center": [0,0,0], "radius": 0.2}]})");
  assert_int_equal(run({bad, "--out", dir + "/out", "--backend", "cpu"}, &out), 3);
  assert_true(contains(out, "fluids[0]: the fluid body does not fit"));
}

// A scene that turns every physics option on and sets their parameters runs (exit 0).
void test_options_scene_runs(void**) {
  const std::string dir = cli_test::make_temp_dir("options");
  std::string out;
  assert_int_equal(run({g_scenes + "/options.json", "--backend", "cpu", "--frames", "2", "--out", dir}, &out),
                   0);
  assert_true(contains(out, "2 frames"));
}

// --dfsph-lists is accepted and, on the CPU backend, changes nothing the run reports.
void test_dfsph_lists_switch(void**) {
  const std::string dir = cli_test::make_temp_dir("dfsph_lists");
  std::string out;
  assert_int_equal(run({g_scenes + "/tiny.json", "--backend", "cpu", "--frames", "1", "--format", "none",
                        "--dfsph-lists", "--out", dir},
                       &out),
                   0);
  assert_true(contains(out, "1 frames") || contains(out, "1 frame"));
}

// CUDA asked for where there is none (a CPU-only build, or no GPU) is a clean error with its
// own code.
void test_cuda_without_gpu_exits_4(void**) {
  sph_context_def def;
  sph_context_def_init(&def);
  def.backend = SPH_BACKEND_CUDA;
  sph_context* context = nullptr;
  const bool have_cuda = sph_context_create(&def, &context) == SPH_OK;
  sph_context_destroy(context);
  const std::string dir = cli_test::make_temp_dir("cuda");
  std::string out;
  const int status = run({g_scenes + "/tiny.json", "--backend", "cuda", "--frames", "1", "--out", dir}, &out);
  if (have_cuda) {
    // A GPU is there: the run works, or the CUDA backend refuses the scene's colliders (this
    // version's backend runs fluid alone) with the same exit code and its reason.
    assert_true(status == 0 || (status == 4 && contains(out, "the CUDA backend cannot run this scene")));
  } else {
    assert_int_equal(status, 4);
    assert_true(contains(out, "the CUDA backend is not available"));
    assert_true(contains(out, "--backend cpu"));
  }
}

// Outputs a build lacks are refused up front with their own code (5), saying what is missing.
void test_missing_outputs_exit_5(void**) {
  const std::string dir = cli_test::make_temp_dir("unavailable");
  const std::string scene = g_scenes + "/tiny.json";
  std::string out;
#ifdef CLI_TEST_NO_OPENVDB
  assert_int_equal(run({scene, "--format", "vdb", "--out", dir}, &out), 5);
  assert_true(contains(out, "this build has no OpenVDB"));
  assert_int_equal(run({scene, "--surface", "--out", dir}, &out), 5);
  assert_true(contains(out, "surfaces need OpenVDB"));
#else
  assert_int_equal(run({scene, "--frames", "0", "--format", "vdb", "--surface", "--out", dir}, &out), 0);
#endif
#ifdef CLI_TEST_NO_PNG
  assert_int_equal(run({scene, "--preview", "--out", dir}, &out), 5);
  assert_true(contains(out, "preview images need libpng"));
#else
  assert_int_equal(run({scene, "--frames", "0", "--format", "none", "--preview", "--out", dir}, &out), 0);
  assert_true(cli_test::file_exists(dir + "/preview_0000.png"));
#endif
}

// SIGINT in the middle of a long run: exit 130, frames 0..k all complete (each PLY parses to
// the length its header gives), nothing under a temporary name, nothing of frame k+1.
void test_interrupt_keeps_only_complete_frames(void**) {
  const std::string dir = cli_test::make_temp_dir("interrupt");
  const pid_t pid = cli_test::start({g_sph_run, g_scenes + "/tiny.json", "--frames", "100000", "--backend",
                                     "cpu", "--format", "ply,csv", "--out", dir, "--threads", "1"},
                                    dir + ".log");
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!cli_test::file_exists(dir + "/fluid_0005.ply") && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  assert_true(cli_test::file_exists(dir + "/fluid_0005.ply"));
  kill(pid, SIGINT);
  const int status = cli_test::wait_for(pid, 60);
  const std::string log = cli_test::read_text(dir + ".log");
  std::printf("%s", log.c_str());
  assert_int_equal(status, 130);
  assert_true(contains(log, "interrupted; frames 0.."));
  std::vector<std::string> names = cli_test::list_dir(dir);
  std::sort(names.begin(), names.end());
  size_t frames = 0;
  for (const std::string& name : names) {
    assert_true(name.find(".tmp") == std::string::npos && name.find(".sph-run-") == std::string::npos);
    if (name.size() > 4 && name.compare(name.size() - 4, 4, ".ply") == 0) {
      char expected[32];
      std::snprintf(expected, sizeof expected, "fluid_%04zu.ply", frames);
      assert_string_equal(name.c_str(), expected);
      cli_test::Particles p;
      std::string error;
      if (!cli_test::read_ply(dir + "/" + name, &p, &error)) std::printf("%s\n", error.c_str());
      assert_true(cli_test::read_ply(dir + "/" + name, &p, &error));
      char csv[32];
      std::snprintf(csv, sizeof csv, "fluid_%04zu.csv", frames);
      cli_test::Particles q;
      assert_true(cli_test::read_csv(dir + "/" + csv, &q, &error));
      assert_int_equal(p.count(), q.count());
      ++frames;
    }
  }
  assert_true(frames >= 6);
  // A .ply and a .csv of every frame and the manifest, nothing else (no staging directory).
  assert_int_equal(names.size(), 2 * frames + 1);
  // The manifest says the same: frames 0..k complete, and how the run ended.
  const std::string manifest = cli_test::read_text(dir + "/sph-run-manifest.jsonl");
  char last[64];
  std::snprintf(last, sizeof last, "{\"end\":\"interrupted\",\"last_frame\":%zu}\n", frames - 1);
  assert_true(manifest.size() > std::strlen(last) &&
              manifest.compare(manifest.size() - std::strlen(last), std::strlen(last), last) == 0);
  size_t complete = 0;
  for (size_t at = 0, end; (end = manifest.find('\n', at)) != std::string::npos; at = end + 1) {
    const std::string line = manifest.substr(at, end - at);
    char head[48];
    std::snprintf(head, sizeof head, "{\"frame\":%zu,", complete);
    if (line.compare(0, std::strlen(head), head) == 0 && contains(line, "\"state\":\"complete\"")) ++complete;
  }
  assert_int_equal(complete, frames);
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
      cmocka_unit_test(test_usage_errors_exit_2),
      cmocka_unit_test(test_scene_errors_exit_3),
      cmocka_unit_test(test_dfsph_lists_switch),
      cmocka_unit_test(test_options_scene_runs),
      cmocka_unit_test(test_cuda_without_gpu_exits_4),
      cmocka_unit_test(test_missing_outputs_exit_5),
      cmocka_unit_test(test_interrupt_keeps_only_complete_frames),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
