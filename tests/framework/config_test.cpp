// Config validation: every kind of bad input gets one clear error with file:line:column, what
// was found and what is valid.

#include "config/yaml_file.h"
#include "core/error.h"
#include "experiment/experiment.h"
#include "test_registry.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

using namespace rtlab;

namespace {

// The message of the InputError that parsing `text` throws ("" if none is thrown).
std::string errorOf(const std::string& text)
{
    const auto registry = test::makeTestRegistry();
    try {
        experiment::parseExperiment(text, "study.yaml", registry);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

const char* kValid = R"(name: study
base:
  scene: sphere
  grid: 16
  techniques:
    isosurface:
      technique: fake_mesher
      params: {resolution: 4, mode: exact}
)";

} // namespace

TEST(ConfigValidation, ValidFileParses)
{
    const auto registry = test::makeTestRegistry();
    const auto e = experiment::parseExperiment(kValid, "study.yaml", registry);
    ASSERT_EQ(e.runs.size(), 1u);
    const auto& params = e.runs[0].techniques.at("isosurface").params;
    EXPECT_EQ(params.getInt("resolution"), 4);
    EXPECT_EQ(params.getString("mode"), "exact");
    EXPECT_EQ(params.getFloat("scale"), 1.0);   // default filled in
    EXPECT_EQ(params.getBool("smooth"), false);  // default filled in
}

TEST(ConfigValidation, UnknownKeyNamesClosestValidKeys)
{
    const std::string err = errorOf(R"(base:
  scene: sphere
  gird: 16
  techniques: {isosurface: {technique: fake_mesher}}
)");
    EXPECT_NE(err.find("study.yaml:3:3:"), std::string::npos) << err;
    EXPECT_NE(err.find("unknown key 'gird'"), std::string::npos) << err;
    EXPECT_NE(err.find("did you mean grid?"), std::string::npos) << err;
}

TEST(ConfigValidation, UnknownParameterNamesClosestParameters)
{
    const std::string err = errorOf(R"(base:
  scene: sphere
  techniques:
    isosurface: {technique: fake_mesher, params: {resolutoin: 3}}
)");
    EXPECT_NE(err.find("study.yaml:4:51:"), std::string::npos) << err;
    EXPECT_NE(err.find("unknown key 'resolutoin'"), std::string::npos) << err;
    EXPECT_NE(err.find("did you mean resolution?"), std::string::npos) << err;
    EXPECT_NE(err.find("technique 'fake_mesher'"), std::string::npos) << err;
}

TEST(ConfigValidation, WrongTypeSaysWhatWasExpected)
{
    const std::string err = errorOf(R"(base:
  scene: sphere
  techniques:
    isosurface:
      technique: fake_mesher
      params:
        resolution: 2.5
)");
    EXPECT_NE(err.find("study.yaml:7:21:"), std::string::npos) << err;
    EXPECT_NE(err.find("expected int in [1, 64] (cells), found '2.5'"), std::string::npos) << err;

    const std::string quoted = errorOf(R"(base:
  scene: sphere
  techniques:
    isosurface: {technique: fake_mesher, params: {smooth: "yes"}}
)");
    EXPECT_NE(quoted.find("study.yaml:4:59:"), std::string::npos) << quoted;
    EXPECT_NE(quoted.find("expected bool"), std::string::npos) << quoted;

    const std::string list = errorOf(R"(base:
  scene: sphere
  techniques:
    isosurface: {technique: fake_mesher, params: {scale: [1, 2]}}
)");
    EXPECT_NE(list.find("expected float in [0, 10] (world units), found a sequence"), std::string::npos)
        << list;
}

TEST(ConfigValidation, OutOfRangeValueGivesTheRange)
{
    const std::string err = errorOf(R"(base:
  scene: sphere
  techniques:
    isosurface: {technique: fake_mesher, params: {scale: 12.5}}
)");
    EXPECT_NE(err.find("study.yaml:4:58:"), std::string::npos) << err;
    EXPECT_NE(err.find("'12.5' is not valid; expected a number in [0, 10] (world units)"), std::string::npos)
        << err;

    const std::string grid = errorOf(R"(base:
  scene: sphere
  grid: 1
  techniques: {isosurface: {technique: fake_mesher}}
)");
    EXPECT_NE(grid.find("study.yaml:3:9:"), std::string::npos) << grid;
    EXPECT_NE(grid.find("expected an integer in [2, 1024]"), std::string::npos) << grid;
}

TEST(ConfigValidation, MissingRequiredKey)
{
    const std::string err = errorOf(R"(base:
  techniques: {isosurface: {technique: fake_mesher}}
)");
    EXPECT_NE(err.find("study.yaml:2:3:"), std::string::npos) << err;
    EXPECT_NE(err.find("base: missing required key 'scene'"), std::string::npos) << err;

    const std::string noBase = errorOf("name: x\n");
    EXPECT_NE(noBase.find("study.yaml:1:1:"), std::string::npos) << noBase;
    EXPECT_NE(noBase.find("missing required key 'base'"), std::string::npos) << noBase;
}

TEST(ConfigValidation, DuplicateKeyNamesBothLines)
{
    const std::string err = errorOf(R"(base:
  scene: sphere
  grid: 16
  grid: 32
  techniques: {isosurface: {technique: fake_mesher}}
)");
    EXPECT_NE(err.find("study.yaml:4:3:"), std::string::npos) << err;
    EXPECT_NE(err.find("duplicate key 'grid' (first given at line 3)"), std::string::npos) << err;
}

TEST(ConfigValidation, UnknownTechniqueSuggestsClosest)
{
    const std::string err = errorOf(R"(base:
  scene: sphere
  techniques:
    isosurface: {technique: fake_meshr}
)");
    EXPECT_NE(err.find("study.yaml:4:29:"), std::string::npos) << err;
    EXPECT_NE(err.find("unknown technique in family 'isosurface' 'fake_meshr'; did you mean fake_mesher?"),
              std::string::npos)
        << err;
}

TEST(ConfigValidation, UnknownFamilySuggestsClosest)
{
    const std::string err = errorOf(R"(base:
  scene: sphere
  techniques:
    isosurfase: {technique: fake_mesher}
)");
    EXPECT_NE(err.find("study.yaml:4:5:"), std::string::npos) << err;
    EXPECT_NE(err.find("unknown technique family 'isosurfase'; did you mean isosurface?"), std::string::npos)
        << err;
    EXPECT_NE(err.find("Valid: isosurface, occlusion, voxel_gi"), std::string::npos) << err;
}

TEST(ConfigValidation, AnUnknownNameWithNothingCloseEndsItsSentence)
{
    const std::string err = errorOf(R"(base:
  scene: sphere
  techniques:
    lighting: {technique: fake_mesher}
)");
    EXPECT_NE(err.find("unknown technique family 'lighting'. Valid: isosurface, occlusion, voxel_gi."),
              std::string::npos)
        << err;
}

TEST(ConfigValidation, NotYaml)
{
    const std::string err = errorOf("base: [unclosed\n  scene: {\n");
    EXPECT_NE(err.find("study.yaml:"), std::string::npos) << err;
    EXPECT_NE(err.find("not valid YAML"), std::string::npos) << err;

    const std::string prose = errorOf("This is a plain text note, not a config.\n");
    EXPECT_NE(prose.find("study.yaml:1:1:"), std::string::npos) << prose;
    EXPECT_NE(prose.find("expected a YAML mapping"), std::string::npos) << prose;

    const std::string binary = errorOf(std::string("\x89PNG\r\n\x1a\n\0\0", 10));
    EXPECT_NE(binary.find("binary"), std::string::npos) << binary;
}

TEST(ConfigValidation, EmptyFile)
{
    for (const char* text : {"", "   \n\n", "# only a comment\n"}) {
        const std::string err = errorOf(text);
        EXPECT_NE(err.find("study.yaml:1:1:"), std::string::npos) << err;
        EXPECT_NE(err.find("the file is empty"), std::string::npos) << err;
    }
}

TEST(ConfigValidation, BadEnumValueSuggestsChoices)
{
    const std::string err = errorOf(R"(base:
  scene: sphere
  techniques:
    isosurface: {technique: fake_mesher, params: {mode: exakt}}
)");
    EXPECT_NE(err.find("study.yaml:4:57:"), std::string::npos) << err;
    EXPECT_NE(err.find("expected one of fast or exact; did you mean exact?"), std::string::npos) << err;
}

TEST(ConfigValidation, UnknownSceneSuggestsClosest)
{
    const std::string err = errorOf(R"(base:
  scene: spere
  techniques: {isosurface: {technique: fake_mesher}}
)");
    EXPECT_NE(err.find("study.yaml:2:10:"), std::string::npos) << err;
    EXPECT_NE(err.find("unknown scene 'spere'; did you mean sphere?"), std::string::npos) << err;
}

TEST(ConfigValidation, MissingFileIsAnInputError)
{
    const auto registry = test::makeTestRegistry();
    try {
        experiment::loadExperiment("/nonexistent/study.yaml", registry);
        FAIL() << "expected an InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent/study.yaml: error: cannot open"), std::string::npos)
            << e.what();
    }
}

TEST(ConfigValidation, LoadsFromDiskWithThePathInMessages)
{
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_config_test";
    std::filesystem::create_directories(dir);
    const auto path = (dir / "bad.yaml").string();
    std::ofstream(path) << "base:\n  scene: sphere\n  colour: red\n  techniques: {isosurface: {technique: fake_mesher}}\n";
    const auto registry = test::makeTestRegistry();
    try {
        experiment::loadExperiment(path, registry);
        FAIL() << "expected an InputError";
    } catch (const InputError& e) {
        EXPECT_EQ(e.location().file, path);
        EXPECT_EQ(e.location().line, 3);
        EXPECT_EQ(e.location().column, 3);
    }
}
