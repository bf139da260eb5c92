// `saarcor`: the command-line front end. This is the only translation unit that includes CLI11
// (it costs ~10 s of compile time per TU); each subcommand's work lives in its own file and is
// reached through a plain options struct.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "testbench/version.h"
// [subcommand headers]
#include "testbench/compare.h"
#include "testbench/cost_cmd.h"
#include "testbench/float_tools.h"
#include "testbench/paper_cmd.h"
#include "testbench/precision_cmd.h"
#include "testbench/render_cmd.h"
#include "testbench/run_journal.h"
#include "testbench/sample_check.h"
#include "testbench/sampling.h"
#include "testbench/scene_cmd.h"
#include "testbench/sweep_cmd.h"
#include "testbench/vectors_cmd.h"

namespace {

// The command line as given, for the run folder's command.txt (--out-dir).
using Command = std::vector<std::string>;

void add_scene(CLI::App& app, saarcor::SceneOptions& scene_opts, int& status) {
  auto* sub = app.add_subcommand(
      "scene", "scene statistics: triangles, objects, instances, kd-trees, bytes per bank");
  sub->add_option("scene", scene_opts.scene, "glTF file or builtin:NAME")->required();
  sub->add_option("--time", scene_opts.time, "animation time in seconds")->capture_default_str();
  sub->add_flag("--json", scene_opts.json, "print one JSON object");
  sub->add_option("--export", scene_opts.export_path, "write the scene as glTF (.glb or .gltf)");
  sub->add_option("--bank-mb", scene_opts.bank_mb, "SRAM bank size in MB")->capture_default_str();
  sub->add_option("--write-image", scene_opts.image_path,
                  "write the memory image as a file (versioned header and the SRAM banks)");
  sub->add_option("--set", scene_opts.set, "kd-tree builder key kd.KEY=VALUE (repeatable)");
  sub->callback([&] { status = saarcor::run_scene(scene_opts); });
}

void add_cost(CLI::App& app, saarcor::CostOptions& cost_opts, int& status) {
  auto* sub = app.add_subcommand("cost", "FP units and internal memory per unit (Table 2)");
  sub->add_option("--preset", cost_opts.preset, "prototype, table2 (beside Table 2), standard")
      ->capture_default_str();
  sub->add_option("--set", cost_opts.set, "cycle model key or lights=N KEY=VALUE (repeatable)");
  sub->add_option("--json", cost_opts.json, "write the figures as JSON");
  sub->callback([&] { status = saarcor::run_cost(cost_opts); });
}

void add_float_info(CLI::App& app, saarcor::FloatInfoOptions& float_info_opts, int& status) {
  auto* sub = app.add_subcommand("float-info", "parameters of a float format; --value rounds X");
  sub->add_option("--format", float_info_opts.format, "eEmM, fp24, fp32, fp16")
      ->capture_default_str();
  sub->add_option("--value", float_info_opts.value, "a number to round into the format");
  sub->callback([&] { status = saarcor::run_float_info(float_info_opts); });
}

void add_float_calc(CLI::App& app, saarcor::FloatCalcOptions& float_calc_opts, int& status) {
  auto* sub = app.add_subcommand("float-calc", "evaluate 'OP A [B]' lines (hex) from stdin");
  sub->add_option("--format", float_calc_opts.format, "eEmM, fp24, fp32, fp16")
      ->capture_default_str();
  sub->add_option("--round", float_calc_opts.round, "rne | rtz")->capture_default_str();
  sub->add_option("--subnormals", float_calc_opts.subnormals, "flush | keep")
      ->capture_default_str();
  sub->callback([&] { status = saarcor::run_float_calc(float_calc_opts); });
}

void add_float_gen(CLI::App& app, saarcor::FloatGenOptions& float_gen_opts, int& status) {
  auto* sub = app.add_subcommand("float-gen", "write TestFloat-style vectors 'A B RESULT'");
  sub->add_option("op", float_gen_opts.op, "add sub mul div sqrt lt le eq min max")->required();
  sub->add_option("--count", float_gen_opts.count, "number of vectors")->capture_default_str();
  sub->add_option("--seed", float_gen_opts.seed, "random seed")->capture_default_str();
  sub->add_option("--format", float_gen_opts.format, "eEmM, fp24, fp32, fp16")
      ->capture_default_str();
  sub->add_option("--round", float_gen_opts.round, "rne | rtz")->capture_default_str();
  sub->add_option("--subnormals", float_gen_opts.subnormals, "flush | keep")->capture_default_str();
  sub->callback([&] { status = saarcor::run_float_gen(float_gen_opts); });
}

// The render options whose presence (not only value) the command reads.
struct RenderGiven {
  CLI::Option* out = nullptr;
  CLI::Option* hits = nullptr;
  CLI::Option* trace_from = nullptr;
  CLI::Option* trace_to = nullptr;
  CLI::Option* frames = nullptr;
  CLI::Option* fps = nullptr;
  CLI::Option* dt = nullptr;
};

void add_render_frame_options(CLI::App* sub, saarcor::RenderOptions& render_opts,
                              RenderGiven& given) {
  sub->add_option("scene", render_opts.scene, "glTF file or builtin:NAME")->required();
  sub->add_option("--model", render_opts.model, "float | fp24 | e7m10..e7m23 | cycle | cycle-e7m23")
      ->capture_default_str();
  sub->add_option("--res", render_opts.res, "resolution WxH")->capture_default_str();
  sub->add_option("--time", render_opts.time, "animation time in seconds");
  given.out =
      sub->add_option("--out", render_opts.out,
                      "output prefix (PREFIX.png, PREFIX.exr; a given .png or .exr is dropped)")
          ->capture_default_str();
  sub->add_flag("--exr", render_opts.exr, "also write PREFIX.exr");
  // A file name, or none with --out-dir (DIR/hits.exr).
  given.hits = sub->add_option("--hits", render_opts.hits,
                               "write the per-pixel hit records as a hit EXR (FILE.exr; with "
                               "--out-dir no name: DIR/hits.exr)")
                   ->expected(0, 1);
  sub->add_option("--report", render_opts.report, "write a JSON report");
  sub->add_option("--out-dir", render_opts.out_dir,
                  "write image, report.json, stats.txt, config.json, command.txt, host.json "
                  "into DIR");
  sub->add_option("--pixel", render_opts.pixel, "trace one pixel x,y and print its hit record");
  sub->add_flag("--shadows", render_opts.shadows, "shadow rays");
  sub->add_option("--depth", render_opts.depth, "secondary-ray depth (0 = primary only)");
  sub->add_option("--bank-mb", render_opts.bank_mb, "SRAM bank size in MB")->capture_default_str();
}

// --sample [SPEC] (testbench/sampling.h): given without SPEC, the default; whether it was given is
// read from the option's count (sample_given).
CLI::Option* add_sample_option(CLI::App* sub, std::string& spec) {
  return sub
      ->add_option("--sample", spec,
                   "cycle model: sample the frame (SMARTS windows) and give each figure a 95 % "
                   "interval; SPEC window=W,period=K,warmup=U,cooldown=C in packets, any subset "
                   "(the rest chosen for the chip and the frame: docs/sampling.md)")
      ->expected(0, 1);
}
bool sample_given(CLI::App* sub) {
  return sub->get_option("--sample")->count() > 0;
}

// --model cycle (testbench/cycle_render.h)
void add_render_cycle_options(CLI::App* sub, saarcor::RenderOptions& render_opts) {
  sub->add_option("--preset", render_opts.cycle.preset,
                  "cycle model preset (prototype, table2, standard)")
      ->capture_default_str();
  sub->add_option("--set", render_opts.cycle.set,
                  "cycle model parameter KEY=VALUE (repeatable; docs/cycle-model.md)");
  sub->add_option("--interval", render_opts.cycle.interval,
                  "cycle model: sample the figures every N cycles into the report");
  sub->add_option("--host-threads", render_opts.cycle.host_threads,
                  "cycle model: 2 = thread programs on a second host thread, 1 = on the "
                  "simulation's thread (default: 2 on a multi-core host; same results)");
  add_sample_option(sub, render_opts.cycle.sample_spec);
  sub->add_option("--vcd", render_opts.cycle.vcd, "cycle model: write a VCD trace");
  sub->add_option("--vcd-from", render_opts.cycle.vcd_from, "first cycle of the VCD trace");
  sub->add_option("--vcd-to", render_opts.cycle.vcd_to, "last cycle of the VCD trace")
      ->capture_default_str();
}

// Traces (docs/traces.md)
void add_render_trace_options(CLI::App* sub, saarcor::RenderOptions& render_opts,
                              RenderGiven& given) {
  sub->add_option("--trace", render_opts.trace.file,
                  "write the request trace: a line per unit request with its transactions "
                  "(fp24, e7mM and cycle models)");
  given.trace_from = sub->add_option("--trace-from", render_opts.trace.from,
                                     "cycle model: first cycle of --trace, --konata, --perfetto");
  given.trace_to = sub->add_option("--trace-to", render_opts.trace.to,
                                   "cycle model: last cycle of --trace, --konata, --perfetto");
  sub->add_option("--konata", render_opts.trace.konata,
                  "cycle model: write a Kanata pipeline log (opens in Konata)");
  sub->add_option("--konata-threads", render_opts.trace.konata_threads,
                  "cycle model: the threads of --konata, e.g. 0,3,8-11 (default: all)");
  sub->add_option("--perfetto", render_opts.trace.perfetto,
                  "cycle model: write a Perfetto / chrome://tracing timeline (trace-event JSON)");
}

// Frame sequences (testbench/frame_sequence.h, docs/frames.md)
void add_render_sequence_options(CLI::App* sub, saarcor::RenderOptions& render_opts,
                                 RenderGiven& given) {
  given.frames = sub->add_option("--frames", render_opts.frames,
                                 "render N frames of the animation: per-frame top-level "
                                 "rebuild, upload over the host bus, frame-buffer swap");
  given.fps = sub->add_option("--fps", render_opts.fps,
                              "frames: frames per animation second (default: the animation's "
                              "length spread over the frames)");
  given.dt = sub->add_option("--dt", render_opts.dt, "frames: animation seconds between frames");
  sub->add_option("--resume", render_opts.resume,
                  "frames: go on with the stopped sequence in run folder DIR, rendering only the "
                  "frames its journal lacks (implies --out-dir DIR)");
  sub->add_flag("--frame-gap", render_opts.frame_gap,
                "frames: one top-level copy, every upload after the frame in flight (instead "
                "of two copies and uploads during it)");
  sub->add_option("--bus-sweep", render_opts.bus_sweep,
                  "frames, cycle model: run the sequence once per host-bus bandwidth "
                  "MB/S,MB/S,... and tabulate which uploads stay hidden");
}

void add_render(CLI::App& app, saarcor::RenderOptions& render_opts, int& status,
                const Command& command) {
  auto* sub = app.add_subcommand(
      "render", "render one frame (or --frames N) with a model; write PNG, EXR, hit EXR, report");
  RenderGiven given;
  add_render_frame_options(sub, render_opts, given);
  add_render_cycle_options(sub, render_opts);
  add_render_trace_options(sub, render_opts, given);
  add_render_sequence_options(sub, render_opts, given);
  sub->callback([&, given, sub] {
    render_opts.cycle.sample = sample_given(sub);
    render_opts.out_given = given.out->count() > 0;
    render_opts.hits_asked = given.hits->count() > 0;
    render_opts.trace.window_given = given.trace_from->count() > 0 || given.trace_to->count() > 0;
    render_opts.frames_given = given.frames->count() > 0;
    render_opts.fps_given = given.fps->count() > 0;
    render_opts.dt_given = given.dt->count() > 0;
    render_opts.argv = command;
    status = saarcor::run_render(render_opts);
  });
}

void add_paper(CLI::App& app, saarcor::PaperOptions& paper_opts, int& status) {
  auto* sub = app.add_subcommand(
      "paper", "the paper's Tables 3 and 4: each stand-in's cycle-model row beside the paper's");
  sub->add_option("--table", paper_opts.table, "1, 2, 3 or 4 (default: 3 and 4)");
  sub->add_flag("--threads", paper_opts.threads,
                "the room's thread curve 1..64 beside the paper's instead of the tables");
  sub->add_option("--scale", paper_opts.scale, "divide the tables' resolutions (quick looks)")
      ->capture_default_str();
  sub->add_option("--scene", paper_opts.scenes, "only this paper scene (repeatable)");
  sub->add_option("--references", paper_opts.references,
                  "folder of the reference glTF models ('' = none)")
      ->capture_default_str();
  sub->add_option("--set", paper_opts.set, "cycle model or kd.* key KEY=VALUE (repeatable)");
  add_sample_option(sub, paper_opts.sample_spec);
  sub->add_option("--csv", paper_opts.csv, "write the rows as CSV");
  sub->add_option("--json", paper_opts.json, "write the rows and every cycle report as JSON");
  sub->add_option("--jobs", paper_opts.jobs,
                  "scenes (or thread counts) rendered at once (default: the host's cores; same "
                  "rows)");
  sub->callback([&, sub] {
    paper_opts.sample = sample_given(sub);
    status = saarcor::run_paper(paper_opts);
  });
}

void add_sweep(CLI::App& app, saarcor::SweepOptions& sweep_opts, int& status,
               const Command& command) {
  auto* sub = app.add_subcommand(
      "sweep", "cycle model over a grid of configurations, each checked against fp24");
  sub->add_option("scene", sweep_opts.scene, "glTF file or builtin:NAME")->required();
  sub->add_option("--vary", sweep_opts.vary,
                  "cycle model key and its values KEY=V1,V2,... (repeatable: the product)")
      ->required();
  sub->add_option("--model", sweep_opts.model, "cycle | cycle-e7m23")->capture_default_str();
  sub->add_option("--res", sweep_opts.res, "resolution WxH")->capture_default_str();
  sub->add_option("--time", sweep_opts.time, "animation time in seconds");
  sub->add_flag("--shadows", sweep_opts.shadows, "shadow rays");
  sub->add_option("--depth", sweep_opts.depth, "secondary-ray depth (0 = primary only)");
  sub->add_option("--bank-mb", sweep_opts.bank_mb, "SRAM bank size in MB")->capture_default_str();
  sub->add_option("--preset", sweep_opts.preset, "cycle model preset (prototype, table2, standard)")
      ->capture_default_str();
  sub->add_option("--set", sweep_opts.set, "cycle model parameter KEY=VALUE for every point");
  sub->add_option("--host-threads", sweep_opts.host_threads,
                  "2 = thread programs on a second host thread, 1 = on the simulation's thread");
  add_sample_option(sub, sweep_opts.sample_spec);
  sub->add_option("--report", sweep_opts.report, "write every point's report as JSON");
  sub->add_option("--csv", sweep_opts.csv, "write the table as CSV");
  sub->add_option("--jobs", sweep_opts.jobs,
                  "points run at once on this host (default: its cores; same rows)");
  sub->add_option("--shard", sweep_opts.shard,
                  "K/N: only shard K of N (every N-th point; merge with sweep-merge)");
  sub->add_option("--out-dir", sweep_opts.out_dir,
                  "write sweep.csv, report.json, stats.txt, config.json, command.txt, host.json "
                  "into DIR (and each point to DIR/journal.txt as it finishes)");
  sub->add_option("--resume", sweep_opts.resume,
                  "go on with the stopped sweep in run folder DIR: run only the points its "
                  "journal lacks (implies --out-dir DIR)");
  sub->add_flag("--pareto", sweep_opts.pareto,
                "mark the points no other point beats in both frame rate and cost (the LUT "
                "estimate unless --pareto-cost says)");
  sub->add_option("--pareto-cost", sweep_opts.pareto_cost,
                  "the cost of --pareto: luts, block_rams, memory_kb or fp_units (implies "
                  "--pareto)");
  sub->callback([&, sub] {
    sweep_opts.argv = command;
    sweep_opts.sample = sample_given(sub);
    status = saarcor::run_sweep(sweep_opts);
  });
}

void add_sweep_merge(CLI::App& app, saarcor::SweepMergeOptions& merge_opts, int& status) {
  auto* sub = app.add_subcommand(
      "sweep-merge", "merge the CSVs of sweep --shard K/N runs into the whole sweep's CSV");
  sub->add_option("parts", merge_opts.parts, "shard CSVs (any order)")->required();
  sub->add_option("-o,--out", merge_opts.out, "the merged CSV")->required();
  sub->callback([&] { status = saarcor::run_sweep_merge(merge_opts); });
}

void add_vectors(CLI::App& app, saarcor::VectorsOptions& vectors_opts, int& status) {
  auto* sub = app.add_subcommand(
      "vectors", "unit transaction vectors for RTL verification: write a sample, or --check");
  sub->add_option("scene", vectors_opts.scene, "glTF file or builtin:NAME (to write vectors)");
  sub->add_option("--unit", vectors_opts.unit, "traversal | transformation | intersection");
  sub->add_option("--count", vectors_opts.count, "vectors to keep (a uniform sample)")
      ->capture_default_str();
  sub->add_option("--seed", vectors_opts.seed, "sample seed")->capture_default_str();
  sub->add_option("--res", vectors_opts.res, "resolution WxH of the frame sampled")
      ->capture_default_str();
  sub->add_option("--time", vectors_opts.time, "animation time in seconds");
  sub->add_option("--bank-mb", vectors_opts.bank_mb, "SRAM bank size in MB")->capture_default_str();
  sub->add_flag("--shadows", vectors_opts.shadows, "the frame with shadow rays");
  sub->add_option("--depth", vectors_opts.depth, "secondary-ray depth (0 = primary only)");
  sub->add_option("--out", vectors_opts.out, "the vector file to write");
  sub->add_option("--check", vectors_opts.check,
                  "check a vector file's outputs against the datapath (exit 2 if any differ)");
  sub->callback([&] { status = saarcor::run_vectors(vectors_opts); });
}

void add_precision(CLI::App& app, saarcor::PrecisionOptions& precision_opts, int& status,
                   const Command& command) {
  auto* sub = app.add_subcommand(
      "precision", "same-triangle share and PSNR of Float<7,m> against the float reference");
  sub->add_option("scene", precision_opts.scene, "glTF file or builtin:NAME")->required();
  sub->add_option("--mantissa", precision_opts.mantissa, "mantissa bits: M or A..B (10..23)")
      ->capture_default_str();
  sub->add_option("--res", precision_opts.res, "resolution WxH")->capture_default_str();
  auto* out =
      sub->add_option(
             "--out", precision_opts.out,
             "output prefix (PREFIX.png plot, PREFIX.json; a given .png or .json is dropped)")
          ->capture_default_str();
  sub->add_option("--bank-mb", precision_opts.bank_mb, "SRAM bank size in MB")
      ->capture_default_str();
  sub->add_option("--out-dir", precision_opts.out_dir,
                  "write precision.png, report.json, stats.txt, config.json, command.txt, "
                  "host.json into DIR");
  sub->callback([&, out] {
    precision_opts.out_given = out->count() > 0;
    precision_opts.argv = command;
    status = saarcor::run_precision(precision_opts);
  });
}

void add_compare(CLI::App& app, saarcor::CompareOptions& compare_opts, int& status) {
  auto* sub = app.add_subcommand("compare", "compare two hit EXRs or two images (B = reference)");
  sub->add_option("a", compare_opts.a, "hit EXR or image A")->required();
  sub->add_option("b", compare_opts.b, "hit EXR or image B (the reference)")->required();
  sub->add_option("--report", compare_opts.report, "write the metrics as JSON");
  sub->add_option("--diff", compare_opts.diff, "write a false-colour difference PNG");
  sub->add_option("--bary-tol", compare_opts.params.bary_tolerance,
                  "edge-tie tolerance on min(u, v, 1-u-v)")
      ->capture_default_str();
  sub->add_option("--grazing", compare_opts.params.grazing_cos, "grazing threshold on |cos|/|D|")
      ->capture_default_str();
  sub->callback([&] { status = saarcor::run_compare(compare_opts); });
}

void add_sample_check(CLI::App& app, saarcor::SampleCheckOptions& opts, int& status) {
  auto* sub = app.add_subcommand(
      "sample-check",
      "sampled against full cycle runs: every built-in and 10 reference models under the "
      "covering design's 8 configurations; per figure mean and max error, interval coverage, "
      "host-time ratio");
  sub->add_option("--scene", opts.scenes, "only this scene (repeatable; default: all)");
  sub->add_option("--references", opts.references, "folder of the reference glTF models")
      ->capture_default_str();
  sub->add_option("--models", opts.models, "reference models to take (without --scene)")
      ->capture_default_str();
  sub->add_option("--res", opts.res, "resolutions WxH (repeatable)")->capture_default_str();
  sub->add_option("--config", opts.configs, "only this covering-design configuration (repeatable)");
  sub->add_option(
      "--sample", opts.sample_spec,
      "SPEC window=W,period=K,warmup=U,cooldown=C (any subset; the rest chosen for the chip and "
      "the frame)");
  sub->add_option("--json", opts.json, "write every case and the summary as JSON");
  sub->add_flag("--quiet", opts.quiet, "no line per case");
  sub->callback([&] { status = saarcor::run_sample_check(opts); });
}

}  // namespace

// The main is thin, as pbrt-v4's cmd/ mains: each subcommand's options are set up by its add_*
// function and its work is done by its run_* function.
int main(int argc, char** argv) {
  CLI::App app{
      "saarcor: cycle-level, bit-accurate model of the SaarCOR dynamic ray tracing "
      "pipeline (Schmittler, Woop et al., 2004)"};
  app.set_version_flag("--version", std::string("saarcor ") + saarcor::kVersion);
  app.require_subcommand(1);
  int status = 0;
  const Command command(argv, argv + argc);

  // [subcommands]
  saarcor::SceneOptions scene_opts;
  add_scene(app, scene_opts, status);
  saarcor::CostOptions cost_opts;
  add_cost(app, cost_opts, status);
  saarcor::FloatInfoOptions float_info_opts;
  add_float_info(app, float_info_opts, status);
  saarcor::FloatCalcOptions float_calc_opts;
  add_float_calc(app, float_calc_opts, status);
  saarcor::FloatGenOptions float_gen_opts;
  add_float_gen(app, float_gen_opts, status);
  saarcor::RenderOptions render_opts;
  add_render(app, render_opts, status, command);
  saarcor::PaperOptions paper_opts;
  add_paper(app, paper_opts, status);
  saarcor::SweepOptions sweep_opts;
  add_sweep(app, sweep_opts, status, command);
  saarcor::SweepMergeOptions merge_opts;
  add_sweep_merge(app, merge_opts, status);
  saarcor::VectorsOptions vectors_opts;
  add_vectors(app, vectors_opts, status);
  saarcor::PrecisionOptions precision_opts;
  add_precision(app, precision_opts, status, command);
  saarcor::CompareOptions compare_opts;
  add_compare(app, compare_opts, status);
  saarcor::SampleCheckOptions sample_check_opts;
  add_sample_check(app, sample_check_opts, status);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const saarcor::Interrupted& e) {
    // SIGINT or SIGTERM stopped a run that kept what finished: one line, 128 + the signal.
    std::fprintf(stderr, "saarcor: %s\n", e.what());
    return 128 + e.signo();
  } catch (const std::exception& e) {
    // Every bad input ends here: one line naming the problem, non-zero exit.
    std::fprintf(stderr, "saarcor: error: %s\n", e.what());
    return 1;
  }
  return status;
}
