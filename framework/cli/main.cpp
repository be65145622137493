// rtlab: run technique comparisons, list plugins, scaffold new techniques.

#include "cli/commands.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <string>

int main(int argc, char** argv)
{
    using namespace rtlab::cli;
    CLI::App app{"rtlab: compare real-time rendering techniques against ground truth"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "rtlab 0.1.0");

    ListOptions list;
    auto* listCmd = app.add_subcommand("list", "List technique families, techniques and their parameters");
    listCmd->add_option("--family", list.family, "Only this family");
    listCmd->add_flag("--json", list.json, "Machine-readable output");

    RunOptions run;
    auto* runCmd = app.add_subcommand("run", "Run an experiment file: every run of its sweep, one row each");
    runCmd->add_option("experiment", run.experimentPath, "Experiment YAML file")->required();
    runCmd->add_option("-o,--output", run.outputDirectory,
                       "Output folder (default: results/<experiment name>)");
    runCmd->add_flag("--dry-run", run.dryRun, "Validate and print the expanded runs; run nothing");
    runCmd->add_option("--shard", run.shard,
                       "Run slice i of N of the sweep (runs k with k mod N = i-1), e.g. 2/4; "
                       "default output results/<name>/shard-i-of-N");

    runCmd->add_flag("!--no-report", run.report, "Do not write plots and report.html after the runs");
    runCmd->add_flag("--slurm", run.slurm,
                     "Submit the sweep to Slurm as an sbatch array (one shard per task) instead of running it");
    runCmd->add_option("--array-size", run.arraySize, "--slurm: array tasks = shards")
        ->capture_default_str()
        ->check(CLI::Range(1, 100000));
    runCmd->add_option("--partition", run.partition, "--slurm: the partition (default: the cluster's)");
    runCmd->add_option("--time", run.timeLimit, "--slurm: time limit per task, e.g. 2:00:00");
    runCmd->add_option("--tasks", run.tasks, "--slurm: submit only these array tasks again, e.g. 2,3")
        ->delimiter(',');

    std::string statusDirectory;
    auto* statusCmd = app.add_subcommand("status", "Progress of each shard of a (Slurm) sweep from its results");
    statusCmd->add_option("results", statusDirectory, "The sweep's results folder (holding shard-i-of-N)")
        ->required()
        ->check(CLI::ExistingDirectory);

    std::string reportDirectory;
    auto* reportCmd = app.add_subcommand("report", "Write the plots and report.html of a results folder");
    reportCmd->add_option("results", reportDirectory, "A results folder (with results.jsonl)")
        ->required()
        ->check(CLI::ExistingDirectory);
    int reportTimeFromFrame = 0;
    reportCmd
        ->add_option("--time-from-frame", reportTimeFromFrame,
                     "Average the time columns of runs of more frames over frames N and later "
                     "(overrides the experiment's report.time_from_frame)")
        ->check(CLI::Range(0, 100000));

    MergeOptions merge;
    auto* mergeCmd = app.add_subcommand("merge", "Join the results of shard folders into one folder");
    mergeCmd->add_option("-o,--output", merge.outputDirectory, "Folder for the joined results")->required();
    mergeCmd->add_option("shards", merge.shardDirectories, "Shard result folders")->required()->check(
        CLI::ExistingDirectory);

    ReferenceOptions ref;
    auto* refCmd = app.add_subcommand(
        "reference", "Embree ground truth of one quantity for a scene, from its rasterised G-buffer");
    refCmd->add_option("scene", ref.scene, "Procedural scene name (cornell_box, tomorrow_town, csg_gallery, "
                                           "ao_testbed) or a scene .yaml file")
        ->required();
    refCmd->add_option("-q,--quantity", ref.quantity, "ao, ao_uniform, obscurance, bent, direct, indirect or full")
        ->capture_default_str()
        ->check(CLI::IsMember({"ao", "ao_uniform", "obscurance", "bent", "direct", "indirect", "full"}));
    refCmd->add_option("-o,--output", ref.outputDirectory, "Folder for <quantity>.exr and <quantity>_stderr.exr")
        ->required();
    refCmd->add_option("--width", ref.width, "Image width in pixels")->capture_default_str()->check(CLI::Range(1, 16384));
    refCmd->add_option("--height", ref.height, "Image height in pixels")->capture_default_str()->check(CLI::Range(1, 16384));
    refCmd->add_option("--frame", ref.frame, "Frame of the scene's animation")->capture_default_str();
    refCmd->add_option("--radius", ref.radius, "Occlusion radius in world units (default unbounded)");
    refCmd->add_option("--falloff", ref.falloff, "Obscurance falloff: linear or smoothstep")
        ->capture_default_str()
        ->check(CLI::IsMember({"linear", "smoothstep"}));
    refCmd->add_option("--bounces", ref.bounces, "Indirect bounces (-1 = unlimited)")->capture_default_str()
        ->check(CLI::Range(-1, 64));
    refCmd->add_option("--target-stderr", ref.targetStdErr, "Absolute per-pixel standard error to reach")
        ->capture_default_str()->check(CLI::PositiveNumber);
    refCmd->add_option("--target-rel-stderr", ref.targetRelStdErr, "Relative per-pixel standard error to reach")
        ->capture_default_str()->check(CLI::NonNegativeNumber);
    refCmd->add_option("--max-samples", ref.maxSamples, "Sample cap per pixel")->capture_default_str()
        ->check(CLI::Range(1, 1 << 24));
    refCmd->add_option("--seed", ref.seed, "Seed of the sample sequences")->capture_default_str();
    refCmd->add_option("--threads", ref.threads, "Worker threads (0 = all)")->capture_default_str()
        ->check(CLI::Range(0, 1024));
    refCmd->add_flag("--no-cache", ref.noCache, "Neither read nor write the on-disk reference cache");
    refCmd->add_option("--gbuffer", ref.gbuffer, "vulkan (rasterised, default) or embree (ray cast)")
        ->capture_default_str()
        ->check(CLI::IsMember({"vulkan", "embree"}));
    refCmd->add_option("--throughput", ref.throughputSamples,
                       "Also trace N samples per pixel and compare Mrays/s with raw rtcIntersect1");

    BestOptions best;
    auto* bestCmd = app.add_subcommand(
        "best", "The lowest-error run within a time budget, or the fastest run within an error bound");
    bestCmd->add_option("results", best.resultsDirectory, "A results folder (with results.jsonl)")
        ->required()
        ->check(CLI::ExistingDirectory);
    auto* maxTime = bestCmd->add_option("--max-time", best.maxTime, "Time budget, e.g. 5ms, 0.5s, 250us");
    auto* maxError = bestCmd->add_option("--max-error", best.maxError, "Error bound (in the error column's unit)");
    maxTime->excludes(maxError);
    bestCmd->add_option("--time-column", best.timeColumn,
                        "Column holding the time in ms (default: the family's, e.g. extract.cpu_ms, technique_ms)");
    bestCmd->add_option("--error-column", best.errorColumn,
                        "Column holding the error (default: the family's, e.g. chamfer.mean, ao.rmse)");
    bestCmd->add_option("--where", best.where,
                        "Only rows with column=value, e.g. --where scene=tomorrow_town --where width=640 (repeatable)");
    bestCmd->add_flag("--per-technique", best.perTechnique,
                      "One answer per technique: each one's best run under the bound (equal-time comparisons)");

    NewTechniqueOptions scaffold;
    auto* newCmd = app.add_subcommand("new-technique",
                                      "Create techniques/<family>/<name>/ from the template of the family");
    newCmd->add_option("family", scaffold.family, "Technique family (see `rtlab list`)")->required();
    newCmd->add_option("name", scaffold.name, "Technique name, snake_case")->required();
    newCmd->add_option("--source-dir", scaffold.sourceDirectory,
                       "Repository root (default: the one rtlab was built from)");

    NewFamilyOptions family;
    auto* newFamilyCmd = app.add_subcommand(
        "new-family", "Create framework/families/<name>/, its technique template, a first technique and an experiment");
    newFamilyCmd->add_option("name", family.name, "Family name, snake_case")->required();
    newFamilyCmd->add_option("--source-dir", family.sourceDirectory,
                             "Repository root (default: the one rtlab was built from)");

    SceneOptions sceneOptions;
    auto* sceneCmd = app.add_subcommand(
        "scene", "What a scene holds (meshes, materials, frames), its loader warnings, load time and "
                 "peak memory");
    sceneCmd->add_option("scene", sceneOptions.scene, "Procedural scene name or scene file")
        ->required();
    sceneCmd->add_option("--frame", sceneOptions.frame, "Frame to build (default 0)")
        ->check(CLI::NonNegativeNumber);

    GpuOptions gpu;
    auto* gpuCmd = app.add_subcommand("gpu", "Show the Vulkan device and time the smoke compute shader");
    gpuCmd->add_option("--device", gpu.device, "Device name substring (default: automatic)");
    gpuCmd->add_flag("--validation", gpu.validation, "Enable the Vulkan validation layer");

    StressCommandOptions stress;
    auto* stressCmd = app.add_subcommand(
        "stress", "Every technique through its family's stress cases (hostile inputs, closed forms, random "
                  "inputs): a pass/fail table, heat maps and a page; exit 1 when a case fails");
    stressCmd->add_option("--family", stress.families, "Only this family (repeatable)");
    stressCmd->add_option("--technique", stress.techniques, "Only this technique (repeatable)");
    stressCmd->add_option("--case", stress.cases, "Only this case (repeatable)");
    stressCmd->add_option("-o,--output", stress.outputDirectory,
                          "Folder for results.csv, heatmap_<family>.png and stress.html")
        ->capture_default_str();
    stressCmd->add_option("--seed", stress.seed, "Seed of the randomised cases")->capture_default_str();
    stressCmd->add_flag("--cpu-only", stress.cpuOnly, "Stress the C++ paths only (no Vulkan device)");
    stressCmd->add_option("--device", stress.device, "Vulkan device name substring (default: automatic)");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? kExitOk : kExitBadInput;
    }

    if (*listCmd)
        return listTechniques(list);
    if (*stressCmd) {
        for (int i = 0; i < argc; ++i)
            stress.commandLine += (i > 0 ? " " : "") + std::string(i == 0 ? "rtlab" : argv[i]);
        return stressCommand(stress);
    }
    if (*runCmd)
        return runExperimentCommand(run);
    if (*statusCmd)
        return statusCommand(statusDirectory);
    if (*newCmd)
        return newTechnique(scaffold);
    if (*newFamilyCmd)
        return newFamily(family);
    if (*gpuCmd)
        return gpuSmoke(gpu);
    if (*sceneCmd)
        return sceneCommand(sceneOptions);
    if (*reportCmd)
        return reportCommand(reportDirectory, reportTimeFromFrame);
    if (*refCmd)
        return referenceCommand(ref);
    if (*mergeCmd)
        return mergeCommand(merge);
    if (*bestCmd) {
        if (best.maxTime.empty() && best.maxError < 0.0) {
            std::fprintf(stderr, "rtlab best: give --max-time or --max-error\n");
            return kExitBadInput;
        }
        return bestCommand(best);
    }
    return kExitBadInput;
}
