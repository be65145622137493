// The `rtlab` command as a user runs it: exit codes, messages, listings, the scaffold.

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>

namespace fs = std::filesystem;

namespace {

struct Result {
    int exitCode = -1;
    std::string output;  // stdout and stderr together
};

Result runRtlab(const std::string& args)
{
    const std::string command = std::string(RTLAB_EXE) + " " + args + " 2>&1";
    Result r;
    std::FILE* pipe = ::popen(command.c_str(), "r");
    if (!pipe)
        return r;
    std::array<char, 4096> buf;
    while (std::size_t n = std::fread(buf.data(), 1, buf.size(), pipe))
        r.output.append(buf.data(), n);
    const int status = ::pclose(pipe);
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

fs::path freshDirectory(const std::string& name)
{
    const auto dir = fs::temp_directory_path() / ("rtlab_cli_test_" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string readFile(const fs::path& p)
{
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

} // namespace

TEST(Cli, HelpOnEverySubcommand)
{
    for (const char* sub : {"", "list", "run", "new-technique", "gpu", "scene", "stress"}) {
        const auto r = runRtlab(std::string(sub) + " --help");
        EXPECT_EQ(r.exitCode, 0) << sub;
        EXPECT_NE(r.output.find("Usage"), std::string::npos) << sub << ": " << r.output;
    }
}

TEST(Cli, NoSubcommandOrUnknownOptionIsAnError)
{
    EXPECT_EQ(runRtlab("").exitCode, 2);
    EXPECT_EQ(runRtlab("list --bogus").exitCode, 2);
    EXPECT_EQ(runRtlab("run").exitCode, 2);  // missing experiment file
}

TEST(Cli, ListShowsTheThreeFamiliesWithParameters)
{
    const auto r = runRtlab("list");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    for (const char* family : {"occlusion:", "isosurface:", "voxel_gi:"})
        EXPECT_NE(r.output.find(family), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("parameter"), std::string::npos) << r.output;

    const auto json = runRtlab("list --json");
    ASSERT_EQ(json.exitCode, 0);
    EXPECT_EQ(json.output.front(), '{');
    EXPECT_NE(json.output.find("\"name\":\"voxel_gi\""), std::string::npos);

    const auto bad = runRtlab("list --family isosurfac");
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.output.find("did you mean isosurface?"), std::string::npos) << bad.output;
}

TEST(Cli, SceneDescribesAModelAndItsLoaderWarnings)
{
    const auto ok = runRtlab("scene " + std::string(RTLAB_SOURCE_DIR) + "/scenes/imported_room.yaml");
    EXPECT_EQ(ok.exitCode, 0) << ok.output;
    EXPECT_NE(ok.output.find("assets/imported_room.obj: 20 triangles"), std::string::npos) << ok.output;
    EXPECT_NE(ok.output.find("warning:     "), std::string::npos) << ok.output;
    EXPECT_NE(ok.output.find("imported_room.mtl"), std::string::npos) << ok.output;
    EXPECT_NE(ok.output.find("peak memory:"), std::string::npos) << ok.output;
    const auto missing = runRtlab("scene no_such_scene.yaml");
    EXPECT_EQ(missing.exitCode, 2) << missing.output;
    EXPECT_NE(missing.output.find("no_such_scene.yaml"), std::string::npos) << missing.output;
}

TEST(Cli, StressWritesItsTableAndExitsWithWhetherEverythingPassed)
{
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_cli_stress";
    std::filesystem::remove_all(dir);
    const auto ok = runRtlab("stress --family isosurface --technique marching_cubes --case sphere --case all_positive "
                             "--cpu-only -o " + dir.string());
    EXPECT_EQ(ok.exitCode, 0) << ok.output;
    EXPECT_NE(ok.output.find("2 of 2 passed"), std::string::npos) << ok.output;
    EXPECT_TRUE(std::filesystem::exists(dir / "results.csv"));
    EXPECT_TRUE(std::filesystem::exists(dir / "heatmap_isosurface.png"));
    EXPECT_TRUE(std::filesystem::exists(dir / "stress.html"));
    const auto bad = runRtlab("stress --technique no_such_technique --cpu-only -o " + dir.string());
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.output.find("marching_cubes"), std::string::npos) << "lists the choices: " << bad.output;
}

TEST(Cli, RunReportsConfigErrorsWithLocationAndExitCode2)
{
    const auto dir = freshDirectory("bad_config");
    const auto path = dir / "bad.yaml";
    std::ofstream(path) << "base:\n  scene: sphere\n  techniques:\n    isosurface: {technique: marching_cube}\n";
    const auto r = runRtlab("run " + path.string());
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.output.find(path.string() + ":4:29: error: unknown technique"), std::string::npos) << r.output;
}

TEST(Cli, DryRunPrintsTheExpandedRuns)
{
    const auto r = runRtlab("run --dry-run " + std::string(RTLAB_SOURCE_DIR) + "/experiments/smoke.yaml");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("smoke: "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("marching_cubes"), std::string::npos) << r.output;
}

TEST(Cli, EveryShippedExperimentValidates)
{
    // The study files under experiments/ are part of the product: each must expand cleanly.
    int count = 0;
    for (const auto& entry : fs::directory_iterator(fs::path(RTLAB_SOURCE_DIR) / "experiments")) {
        if (entry.path().extension() != ".yaml")
            continue;
        const auto r = runRtlab("run --dry-run " + entry.path().string());
        EXPECT_EQ(r.exitCode, 0) << entry.path() << ":\n" << r.output;
        ++count;
    }
    EXPECT_GE(count, 3);
}

TEST(Cli, NewTechniqueScaffoldsFromTheTemplate)
{
    const auto root = freshDirectory("scaffold");
    fs::create_directories(root / "techniques");
    fs::copy(fs::path(RTLAB_SOURCE_DIR) / "techniques" / "_template", root / "techniques" / "_template",
             fs::copy_options::recursive);
    const auto r = runRtlab("new-technique occlusion my_ao --source-dir " + root.string());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const auto folder = root / "techniques" / "occlusion" / "my_ao";
    for (const char* f : {"CMakeLists.txt", "my_ao.cpp", "my_ao_test.cpp", "README.md"}) {
        ASSERT_TRUE(fs::exists(folder / f)) << f;
        EXPECT_EQ(readFile(folder / f).find('@'), std::string::npos) << f << " has an unreplaced placeholder";
    }
    EXPECT_NE(readFile(folder / "CMakeLists.txt").find("rtlab_add_technique(my_ao FAMILY occlusion"),
              std::string::npos);
    EXPECT_NE(readFile(folder / "my_ao.cpp").find("RTLAB_REGISTER_TECHNIQUE(occlusion, my_ao, MyAo)"),
              std::string::npos);

    // A second time: the folder exists, nothing is overwritten.
    const auto again = runRtlab("new-technique occlusion my_ao --source-dir " + root.string());
    EXPECT_EQ(again.exitCode, 2);
    EXPECT_NE(again.output.find("already exists"), std::string::npos);
    // Bad names and families.
    EXPECT_EQ(runRtlab("new-technique occlusion MyAO --source-dir " + root.string()).exitCode, 2);
    const auto fam = runRtlab("new-technique oclusion x --source-dir " + root.string());
    EXPECT_EQ(fam.exitCode, 2);
    EXPECT_NE(fam.output.find("did you mean occlusion?"), std::string::npos) << fam.output;
}

TEST(Cli, BestAnswersPerTechniqueWithTheFamilysColumnsAndFilters)
{
    // A hand-made results table with a known answer: under RMSE 0.05 on scene "a", technique t's
    // cheapest run is t2 (20 ms), u's is u1 (15 ms); rows of scene "b" are filtered out.
    const auto dir = freshDirectory("best");
    std::ofstream(dir / "results.jsonl")
        << R"({"run_id":"t1","status":"ok","family":"occlusion","scene":"a","technique":"t","technique_ms":10,"ao.rmse":0.08}
{"run_id":"t2","status":"ok","family":"occlusion","scene":"a","technique":"t","technique_ms":20,"ao.rmse":0.04}
{"run_id":"t3","status":"ok","family":"occlusion","scene":"a","technique":"t","technique_ms":40,"ao.rmse":0.02}
{"run_id":"u1","status":"ok","family":"occlusion","scene":"a","technique":"u","technique_ms":15,"ao.rmse":0.05}
{"run_id":"u0","status":"ok","family":"occlusion","scene":"b","technique":"u","technique_ms":1,"ao.rmse":0.01}
)";
    const auto perTechnique = runRtlab("best " + dir.string() + " --max-error 0.05 --per-technique --where scene=a");
    ASSERT_EQ(perTechnique.exitCode, 0) << perTechnique.output;
    const auto u = perTechnique.output.find("(u1)"), t = perTechnique.output.find("(t2)");
    ASSERT_NE(u, std::string::npos) << perTechnique.output;
    ASSERT_NE(t, std::string::npos) << perTechnique.output;
    EXPECT_LT(u, t) << "cheapest first: " << perTechnique.output;
    const auto single = runRtlab("best " + dir.string() + " --max-time 25ms --where scene=a");
    ASSERT_EQ(single.exitCode, 0) << single.output;
    EXPECT_EQ(single.output.rfind("t2", 0), 0u) << "lowest error within 25 ms: " << single.output;
    const auto bad = runRtlab("best " + dir.string() + " --max-error 0.05 --where scene");
    EXPECT_EQ(bad.exitCode, 2) << bad.output;
    EXPECT_NE(bad.output.find("column=value"), std::string::npos) << bad.output;
}
