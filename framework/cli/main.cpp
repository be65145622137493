// rtlab: run technique comparisons, list plugins, scaffold new techniques.

#include "cli/commands.h"

#include <CLI/CLI.hpp>

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

    NewTechniqueOptions scaffold;
    auto* newCmd = app.add_subcommand("new-technique",
                                      "Create techniques/<family>/<name>/ from the template of the family");
    newCmd->add_option("family", scaffold.family, "Technique family (see `rtlab list`)")->required();
    newCmd->add_option("name", scaffold.name, "Technique name, snake_case")->required();
    newCmd->add_option("--source-dir", scaffold.sourceDirectory,
                       "Repository root (default: the one rtlab was built from)");

    GpuOptions gpu;
    auto* gpuCmd = app.add_subcommand("gpu", "Show the Vulkan device and time the smoke compute shader");
    gpuCmd->add_option("--device", gpu.device, "Device name substring (default: automatic)");
    gpuCmd->add_flag("--validation", gpu.validation, "Enable the Vulkan validation layer");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? kExitOk : kExitBadInput;
    }

    if (*listCmd)
        return listTechniques(list);
    if (*runCmd)
        return runExperimentCommand(run);
    if (*newCmd)
        return newTechnique(scaffold);
    if (*gpuCmd)
        return gpuSmoke(gpu);
    return kExitBadInput;
}
