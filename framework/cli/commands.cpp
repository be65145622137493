#include "cli/commands.h"

#include "core/error.h"
#include "core/json.h"
#include "core/strings.h"
#include "experiment/analysis.h"
#include "experiment/experiment.h"
#include "experiment/runner.h"
#include "plugin/technique.h"
#include "report/report.h"

#include <fmt/core.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <regex>

namespace rtlab::cli {

namespace fs = std::filesystem;

std::string defaultSourceDirectory()
{
    if (const char* env = std::getenv("RTLAB_SOURCE_DIR"); env && *env)
        return env;
    return RTLAB_BUILT_FROM_SOURCE_DIR;
}

// ---------------------------------------------------------------------------------------- list

static std::string specJson(const config::ParamSpec& s)
{
    JsonObject o;
    o.add("name", s.name).add("type", config::toString(s.type));
    o.addRaw("default", s.type == config::ParamType::String || s.type == config::ParamType::Enum
                            ? jsonEscape(config::formatValue(s.defaultValue))
                            : config::formatValue(s.defaultValue));
    o.add("range", s.describeRange()).add("unit", s.unit).add("doc", s.doc);
    return o.str();
}

int listTechniques(const ListOptions& options)
{
    const auto& registry = plugin::builtinRegistry();
    std::vector<std::string> families = registry.familyNames();
    if (!options.family.empty()) {
        if (!registry.findFamily(options.family)) {
            const auto close = closestNames(options.family, families);
            fmt::print(stderr, "rtlab list: unknown family '{}'{}. Families: {}.\n", options.family,
                       close.empty() ? "" : "; did you mean " + joinList(close, "or") + "?",
                       joinList(families));
            return kExitBadInput;
        }
        families = {options.family};
    }
    if (options.json) {
        std::vector<std::string> familyJson;
        for (const auto& f : families) {
            const auto* info = registry.findFamily(f);
            std::vector<std::string> techniques;
            for (const auto* t : registry.techniques(f)) {
                std::vector<std::string> params;
                for (const auto& s : t->schema.specs())
                    params.push_back(specJson(s));
                techniques.push_back(JsonObject()
                                         .add("name", t->info.name)
                                         .add("summary", t->info.summary)
                                         .add("reference", t->info.reference)
                                         .add("seed", t->info.seed)
                                         .addRaw("parameters", jsonArray(params))
                                         .str());
            }
            std::vector<std::string> metricsJson;
            for (const auto& m : info->metrics)
                metricsJson.push_back(JsonObject().add("name", m.name).add("doc", m.doc).str());
            familyJson.push_back(
                JsonObject()
                    .add("name", f)
                    .add("summary", info->summary)
                    .add("input", info->input)
                    .add("output", info->output)
                    .add("ground_truth", info->groundTruth)
                    .add("domain",
                         std::string(info->domain == plugin::FamilyDomain::Volume ? "volume"
                                                                                  : "screen"))
                    .add("runnable", bool(info->runtime))
                    .addRaw("metrics", jsonArray(metricsJson))
                    .addRaw("techniques", jsonArray(techniques))
                    .str());
        }
        fmt::print("{}\n", JsonObject().addRaw("families", jsonArray(familyJson)).str());
        return kExitOk;
    }
    for (const auto& f : families) {
        const auto* info = registry.findFamily(f);
        fmt::print("{}: {}\n", f, info->summary);
        fmt::print("  input:        {}\n  output:       {}\n  ground truth: {}\n", info->input,
                   info->output, info->groundTruth);
        fmt::print("  runs on:      {}\n", info->domain == plugin::FamilyDomain::Volume
                                               ? "a sampled volume (`grid`), in a run of its own"
                                               : "the shared screen-space frame (`resolution`, "
                                                 "`frames`), with any other screen family");
        if (!info->runtime)
            fmt::print("  (cannot run in experiments yet: the family registers no passes)\n");
        if (!info->metrics.empty()) {
            fmt::print("  metrics (experiment key `metrics:`; default all):\n");
            for (const auto& m : info->metrics)
                fmt::print("    {:<20} {}\n", m.name, m.doc);
        }
        const auto techniques = registry.techniques(f);
        if (techniques.empty())
            fmt::print("  (no techniques yet: `rtlab new-technique {} <name>` adds one)\n", f);
        for (const auto* t : techniques) {
            fmt::print("\n  {}: {}\n", t->info.name, t->info.summary);
            if (!t->info.reference.empty())
                fmt::print("    after: {}\n", t->info.reference);
            if (t->schema.empty()) {
                fmt::print("    (no parameters)\n");
                continue;
            }
            fmt::print("    {:<22} {:<6} {:<10} {:<22} {:<12} {}\n", "parameter", "type", "default",
                       "range", "unit", "doc");
            for (const auto& s : t->schema.specs())
                fmt::print("    {:<22} {:<6} {:<10} {:<22} {:<12} {}\n", s.name,
                           config::toString(s.type), config::formatValue(s.defaultValue),
                           s.describeRange(), s.unit, s.doc);
        }
        fmt::print("\n");
    }
    return kExitOk;
}

// ----------------------------------------------------------------------------------------- run

int runExperimentCommand(const RunOptions& options)
{
    const auto& registry = plugin::builtinRegistry();
    experiment::Experiment e;
    try {
        e = experiment::loadExperiment(options.experimentPath, registry);
    } catch (const InputError& error) {
        fmt::print(stderr, "{}\n", error.what());
        return kExitBadInput;
    }
    if (options.slurm)
        return submitSlurmCommand(options, e);
    if (options.dryRun) {
        fmt::print("{}: {} run(s){}\n", e.name, e.runs.size(),
                   e.sweepKeys.empty() ? "" : " over " + joinList(e.sweepKeys));
        for (std::size_t i = 0; i < e.runs.size(); ++i) {
            const auto& r = e.runs[i];
            std::string techniques;
            for (const auto& [family, choice] : r.techniques)
                techniques +=
                    fmt::format(" {}={}({})", family, choice.technique, choice.params.toString());
            std::string size =
                r.volume ? fmt::format("grid={}", r.grid)
                         : fmt::format("resolution={}x{} frames={}", r.width, r.height, r.frames);
            if (!r.cameraPath.empty())
                size += " camera_path=" + r.cameraPath;
            if (!r.metrics.empty())
                size += " metrics=" + joinList(r.metrics);
            if (!r.culling)
                size += " frame.culling=false";
            if (!r.gbufferOnGpu)
                size += " frame.gbuffer_on_gpu=false";
            if (r.lighting)
                size += fmt::format(" frame.lighting={}@{}EV", r.tonemapper, r.exposureEv);
            if (!r.reference.quantity.empty() || r.reference.radius > 0.0)
                size += fmt::format(
                    " reference={}{}",
                    r.reference.quantity.empty() ? "declared" : r.reference.quantity,
                    r.reference.radius > 0.0 ? fmt::format("@{}", r.reference.radius) : "");
            fmt::print("  {:>4}  {}  scene={} {}{}\n", i + 1, r.id(), r.scene, size, techniques);
        }
        return kExitOk;
    }
    experiment::RunnerOptions runnerOptions;
    runnerOptions.outputDirectory = options.outputDirectory;
    if (!options.shard.empty()) {
        try {
            experiment::parseShard(options.shard, runnerOptions);
        } catch (const InputError& error) {
            fmt::print(stderr, "{}\n", error.what());
            return kExitBadInput;
        }
    }
    const auto summary = experiment::runExperiment(e, registry, runnerOptions);
    fmt::print("{}: {} run(s){}: {} computed, {} already done, {} failed\n", e.name, summary.total,
               options.shard.empty() ? "" : " in shard " + options.shard, summary.succeeded,
               summary.alreadyDone, summary.failed);
    fmt::print("results: {}/results.csv (and results.jsonl, manifest.json)\n",
               summary.outputDirectory);
    if (options.report && summary.succeeded + summary.alreadyDone > 0 &&
        reportCommand(summary.outputDirectory) != kExitOk)
        return kExitFailed;
    if (summary.failed > 0) {
        fmt::print(stderr,
                   "{} run(s) failed; their errors are in the 'error' column of the results.\n",
                   summary.failed);
        return kExitFailed;
    }
    return kExitOk;
}

// ------------------------------------------------------------------------------- new-technique

static std::string toPascalCase(const std::string& snake)
{
    std::string out;
    bool upper = true;
    for (char c : snake) {
        if (c == '_') {
            upper = true;
            continue;
        }
        out += upper ? char(std::toupper(static_cast<unsigned char>(c))) : c;
        upper = false;
    }
    return out;
}

// Copies every regular file of `templateDir` into `target` with the substitutions applied, the
// ".in" suffix dropped (unless keepSuffix) and `placeholder` in file names replaced by `name`.
static std::vector<std::string>
fillTemplate(const fs::path& templateDir, const fs::path& target, const std::string& placeholder,
             const std::string& name,
             const std::vector<std::pair<std::string, std::string>>& substitutions,
             const std::vector<std::string>& excluded = {}, bool keepSuffix = false)
{
    fs::create_directories(target);
    std::vector<std::string> written;
    for (const auto& entry : fs::directory_iterator(templateDir)) {
        if (!entry.is_regular_file())
            continue;
        std::string fileName = entry.path().filename().string();
        if (std::find(excluded.begin(), excluded.end(), fileName) != excluded.end())
            continue;
        if (!keepSuffix && fileName.ends_with(".in"))
            fileName.resize(fileName.size() - 3);
        if (!placeholder.empty())
            for (auto pos = fileName.find(placeholder); pos != std::string::npos;
                 pos = fileName.find(placeholder))
                fileName.replace(pos, placeholder.size(), name);
        std::string text = readTextFile(entry.path().string());
        for (const auto& [from, to] : substitutions)
            for (auto pos = text.find(from); pos != std::string::npos;
                 pos = text.find(from, pos + to.size()))
                text.replace(pos, from.size(), to);
        std::ofstream(target / fileName) << text;
        written.push_back(fileName);
    }
    std::sort(written.begin(), written.end());
    return written;
}

int newTechnique(const NewTechniqueOptions& options)
{
    const auto& registry = plugin::builtinRegistry();
    if (!registry.findFamily(options.family)) {
        const auto close = closestNames(options.family, registry.familyNames());
        fmt::print(stderr, "rtlab new-technique: unknown family '{}'{}. Families: {}.\n",
                   options.family,
                   close.empty() ? "" : "; did you mean " + joinList(close, "or") + "?",
                   joinList(registry.familyNames()));
        return kExitBadInput;
    }
    if (!std::regex_match(options.name, std::regex("[a-z][a-z0-9_]*")) ||
        options.name.back() == '_') {
        fmt::print(
            stderr,
            "rtlab new-technique: name '{}' must be snake_case: a lowercase letter, then lowercase "
            "letters, digits and single underscores (e.g. my_ao)\n",
            options.name);
        return kExitBadInput;
    }
    const fs::path root =
        options.sourceDirectory.empty() ? defaultSourceDirectory() : options.sourceDirectory;
    const fs::path templateDir = root / "techniques" / "_template" / options.family;
    const fs::path target = root / "techniques" / options.family / options.name;
    if (!fs::is_directory(templateDir)) {
        fmt::print(stderr, "rtlab new-technique: no template for family '{}' at {}\n",
                   options.family, templateDir.string());
        return kExitEnvironment;
    }
    if (fs::exists(target)) {
        fmt::print(stderr, "rtlab new-technique: {} already exists; choose another name\n",
                   target.string());
        return kExitBadInput;
    }
    const auto written = fillTemplate(templateDir, target, "technique", options.name,
                                      {{"@NAME@", options.name},
                                       {"@CLASS@", toPascalCase(options.name)},
                                       {"@FAMILY@", options.family},
                                       {"@FAMILY_CLASS@", toPascalCase(options.family)}});
    fmt::print("created {}/ ({})\n", target.string(), joinList(written));
    fmt::print("next: rebuild (cmake --build build) and it appears in `rtlab list --family {}`;\n"
               "      its unit test runs as ctest -R {}_{}\n",
               options.family, options.family, options.name);
    return kExitOk;
}

// ---------------------------------------------------------------------------------- new-family

int newFamily(const NewFamilyOptions& options)
{
    const auto& registry = plugin::builtinRegistry();
    if (!std::regex_match(options.name, std::regex("[a-z][a-z0-9_]*")) ||
        options.name.back() == '_' || options.name.front() == '_') {
        fmt::print(stderr,
                   "rtlab new-family: name '{}' must be snake_case: a lowercase letter, then "
                   "lowercase letters, "
                   "digits and single underscores (e.g. volumetric_fog)\n",
                   options.name);
        return kExitBadInput;
    }
    const fs::path root =
        options.sourceDirectory.empty() ? defaultSourceDirectory() : options.sourceDirectory;
    const fs::path templateDir = root / "framework" / "families" / "_template";
    const fs::path familyDir = root / "framework" / "families" / options.name;
    const fs::path techniqueTemplateDir = root / "techniques" / "_template" / options.name;
    const std::string example = options.name + "_example";
    const fs::path exampleDir = root / "techniques" / options.name / example;
    const fs::path experimentFile = root / "experiments" / (options.name + ".yaml");
    if (registry.findFamily(options.name) || fs::exists(familyDir)) {
        fmt::print(stderr, "rtlab new-family: family '{}' already exists; choose another name\n",
                   options.name);
        return kExitBadInput;
    }
    if (!fs::is_directory(templateDir)) {
        fmt::print(stderr, "rtlab new-family: no family template at {}\n", templateDir.string());
        return kExitEnvironment;
    }
    for (const fs::path& p : {techniqueTemplateDir, exampleDir, experimentFile})
        if (fs::exists(p)) {
            fmt::print(stderr, "rtlab new-family: {} already exists; choose another name\n",
                       p.string());
            return kExitBadInput;
        }
    const std::string familyClass = toPascalCase(options.name);
    // The family folder, without the technique template and the experiment.
    std::vector<std::string> written =
        fillTemplate(templateDir, familyDir, "NAME", options.name,
                     {{"@NAME@", options.name}, {"@CLASS@", familyClass}}, {"experiment.yaml.in"});
    fmt::print("created {}/ ({})\n", familyDir.string(), joinList(written));
    // The technique template of the new family: @FAMILY@ filled in, @NAME@ and @CLASS@ left for
    // `rtlab new-technique`.
    written = fillTemplate(templateDir / "technique", techniqueTemplateDir, "", "",
                           {{"@FAMILY@", options.name}, {"@FAMILY_CLASS@", familyClass}}, {},
                           /*keepSuffix=*/true);
    fmt::print("created {}/ ({})\n", techniqueTemplateDir.string(), joinList(written));
    written = fillTemplate(techniqueTemplateDir, exampleDir, "technique", example,
                           {{"@NAME@", example}, {"@CLASS@", toPascalCase(example)}});
    fmt::print("created {}/ ({})\n", exampleDir.string(), joinList(written));
    std::string study = readTextFile((templateDir / "experiment.yaml.in").string());
    for (auto pos = study.find("@NAME@"); pos != std::string::npos;
         pos = study.find("@NAME@", pos + options.name.size()))
        study.replace(pos, 6, options.name);
    fs::create_directories(experimentFile.parent_path());
    std::ofstream(experimentFile) << study;
    fmt::print("created {}\n", experimentFile.string());
    fmt::print("next: rebuild (cmake --build build); `rtlab list --family {0}` shows it;\n"
               "      build/rtlab run experiments/{0}.yaml writes results/{0}/report.html\n",
               options.name);
    return kExitOk;
}

// ------------------------------------------------------------------------------------- report

int reportCommand(const std::string& resultsDirectory, int timeFromFrame)
{
    try {
        const report::ReportSummary s =
            report::writeStudyReport(resultsDirectory, plugin::builtinRegistry(), timeFromFrame);
        fmt::print("report: {} ({} plots in {}/plots, each .png and .pdf)\n", s.html,
                   s.plots.size(), resultsDirectory);
        if (s.equalErrorRuns > 0)
            fmt::print(
                "equal-error speed-ups: {} ({} run(s) against their family's sampling baseline)\n",
                s.equalError, s.equalErrorRuns);
        return kExitOk;
    } catch (const std::exception& e) {
        fmt::print(stderr, "rtlab report: {}\n", e.what());
        return kExitFailed;
    }
}

// -------------------------------------------------------------------------------- merge, best

int mergeCommand(const MergeOptions& options)
{
    try {
        const std::size_t rows =
            experiment::mergeShards(options.shardDirectories, options.outputDirectory);
        fmt::print("merged {} shard(s): {} row(s) in {}/results.csv\n",
                   options.shardDirectories.size(), rows, options.outputDirectory);
        return kExitOk;
    } catch (const Error& e) {
        fmt::print(stderr, "rtlab merge: {}\n", e.what());
        return kExitBadInput;
    }
}

int bestCommand(const BestOptions& options)
{
    experiment::BestQuery query;
    if (!options.maxTime.empty()) {
        try {
            query.maxCost = experiment::parseDurationMs(options.maxTime);
        } catch (const std::invalid_argument& e) {
            fmt::print(stderr, "rtlab best: --max-time: {}\n", e.what());
            return kExitBadInput;
        }
    } else {
        query.maxError = options.maxError;
    }
    auto rows = experiment::loadResults(options.resultsDirectory);
    if (rows.empty()) {
        fmt::print(stderr, "rtlab best: {}/results.jsonl has no rows\n", options.resultsDirectory);
        return kExitBadInput;
    }
    for (const auto& filter : options.where) {
        const auto eq = filter.find('=');
        if (eq == std::string::npos || eq == 0) {
            fmt::print(stderr, "rtlab best: --where '{}': expected column=value\n", filter);
            return kExitBadInput;
        }
        const std::string column = filter.substr(0, eq), value = filter.substr(eq + 1);
        std::erase_if(rows, [&](const experiment::Row& r) {
            auto it = r.find(column);
            return it == r.end() || it->second != value;
        });
    }
    if (rows.empty()) {
        fmt::print(stderr, "rtlab best: no row matches {}\n", joinList(options.where, "and"));
        return kExitBadInput;
    }
    // Default columns: those the family's report uses.
    query.costColumn = options.timeColumn;
    query.errorColumn = options.errorColumn;
    if (query.costColumn.empty() || query.errorColumn.empty()) {
        const auto family = rows.front().find("family");
        try {
            const report::FamilyColumns columns = report::getFamilyColumns(
                plugin::builtinRegistry(), family == rows.front().end() ? "" : family->second);
            if (query.costColumn.empty())
                query.costColumn = columns.cost;
            if (query.errorColumn.empty())
                query.errorColumn = columns.error;
        } catch (const Error&) {
            fmt::print(
                stderr,
                "rtlab best: the rows name no family with default columns; give --time-column and "
                "--error-column\n");
            return kExitBadInput;
        }
    }
    for (const auto* column : {&query.costColumn, &query.errorColumn}) {
        bool found = false;
        std::vector<std::string> columns;
        for (const auto& row : rows)
            for (const auto& [k, v] : row) {
                if (std::find(columns.begin(), columns.end(), k) == columns.end())
                    columns.push_back(k);
                found = found || k == *column;
            }
        if (!found) {
            const auto close = closestNames(*column, columns);
            fmt::print(stderr, "rtlab best: no column '{}' in the results{}\n", *column,
                       close.empty() ? "" : "; did you mean " + joinList(close, "or") + "?");
            return kExitBadInput;
        }
    }
    const std::string bound =
        query.maxCost >= 0.0 ? query.costColumn + " <= " + options.maxTime
                             : query.errorColumn + " <= " + config::formatValue(options.maxError);
    if (options.perTechnique) {
        // Each technique's best run under the bound, cheapest (or most accurate) first.
        std::map<std::string, std::vector<experiment::Row>> byTechnique;
        for (const auto& r : rows)
            byTechnique[r.count("technique") ? r.at("technique") : "?"].push_back(r);
        std::vector<std::pair<double, std::string>> lines;
        for (const auto& [technique, techniqueRows] : byTechnique) {
            const long b = experiment::findBest(techniqueRows, query);
            if (b < 0) {
                lines.push_back({std::numeric_limits<double>::infinity(),
                                 fmt::format("  {:<16} no run satisfies {}", technique, bound)});
                continue;
            }
            const auto& row = techniqueRows[std::size_t(b)];
            const double cost = experiment::getNumber(row, query.costColumn);
            const double error = experiment::getNumber(row, query.errorColumn);
            std::string params;
            for (const auto& [k, v] : row)
                if (k.rfind("param.", 0) == 0)
                    params += (params.empty() ? "" : " ") + k.substr(6) + "=" + v;
            lines.push_back(
                {query.maxCost >= 0.0 ? error : cost,
                 fmt::format("  {:<16} {}={:.4g} {}={:.4g}  {}  ({})", technique, query.costColumn,
                             cost, query.errorColumn, error, params, row.at("run_id"))});
        }
        std::sort(lines.begin(), lines.end());
        fmt::print("best run per technique with {}:\n", bound);
        for (const auto& [key, line] : lines)
            fmt::print("{}\n", line);
        return kExitOk;
    }
    const long best = experiment::findBest(rows, query);
    if (best < 0) {
        fmt::print("no run satisfies {}\n", bound);
        return kExitFailed;
    }
    const auto& row = rows[std::size_t(best)];
    fmt::print("{}\n", row.at("run_id"));
    fmt::print("  {:<22} {}\n", query.costColumn, row.at(query.costColumn));
    fmt::print("  {:<22} {}\n", query.errorColumn, row.at(query.errorColumn));
    for (const auto& [k, v] : row)
        if (k == "scene" || k == "technique" || k == "grid" || k.rfind("param.", 0) == 0)
            fmt::print("  {:<22} {}\n", k, v);
    return kExitOk;
}

} // namespace rtlab::cli
