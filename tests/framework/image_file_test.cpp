// The size checks before an image file is decoded: EXR headers that claim more pixels than rtlab
// reads, or more chunks than the file holds, are clear errors; rtlab's own files pass.

#include "core/error.h"
#include "core/image_file_size.h"
#include "experiment/image_files.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

using namespace rtlab;
namespace fs = std::filesystem;

namespace {

std::string readBytes(const fs::path& p)
{
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

fs::path writeBytes(const std::string& name, const std::string& bytes)
{
    const fs::path p = fs::temp_directory_path() / ("rtlab_image_file_test_" + name);
    std::ofstream(p, std::ios::binary) << bytes;
    return p;
}

//! `bytes` with the dataWindow box replaced by (0, 0) - (xMax, yMax).
std::string setDataWindow(std::string bytes, std::int32_t xMax, std::int32_t yMax)
{
    const std::string key = std::string("dataWindow\0box2i\0", 17);
    const std::size_t at = bytes.find(key);
    EXPECT_NE(at, std::string::npos);
    const std::int32_t box[4] = {0, 0, xMax, yMax};
    std::memcpy(bytes.data() + at + key.size() + 4, box, sizeof box);
    return bytes;
}

} // namespace

TEST(ImageFileSize, PositiveAndAtMostTwoToThe26Values)
{
    EXPECT_NO_THROW(checkImageFileSize("a.exr", 3840, 2160, 7));
    EXPECT_NO_THROW(checkImageFileSize("a.exr", 8192, 8192, 1));
    EXPECT_THROW(checkImageFileSize("a.exr", 8192, 8193, 1), Error);
    EXPECT_THROW(checkImageFileSize("a.exr", 0, 10, 1), Error);
    EXPECT_THROW(checkImageFileSize("a.exr", 10, -1, 3), Error);
    EXPECT_THROW(checkImageFileSize("a.exr", 1ll << 40, 1ll << 40, 1), Error); // no overflow
}

// writePng's files read back as display values (8 bits: within half a step of 1/255), and an
// EXR is not taken for a PNG.
TEST(PngFile, ReadsBackWhatWritePngWrote)
{
    Image<glm::vec3> image(4, 2, glm::vec3(0.0f));
    for (std::size_t i = 0; i < image.pixels.size(); ++i)
        image.pixels[i] = glm::vec3(float(i) / 7.0f, 1.0f - float(i) / 7.0f, 0.5f);
    const fs::path png = fs::temp_directory_path() / "rtlab_image_file_test.png";
    experiment::writePng(image, png.string());
    const Image<glm::vec3> back = experiment::readPngRgb(png.string());
    ASSERT_EQ(back.width, 4);
    ASSERT_EQ(back.height, 2);
    for (std::size_t i = 0; i < image.pixels.size(); ++i)
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(back.pixels[i][c], image.pixels[i][c], 0.5f / 255.0f + 1e-6f) << i;
    const fs::path exr = fs::temp_directory_path() / "rtlab_image_file_test_not_png.exr";
    experiment::writeExr(image, exr.string());
    EXPECT_THROW(experiment::readPngRgb(exr.string()), Error);
}

TEST(ExrHeader, RtlabsOwnFilesPassAndHugeOrTruncatedHeadersAreRefused)
{
    Image<glm::vec3> image(5, 3, glm::vec3(0.25f, 0.5f, 0.75f));
    const fs::path good = fs::temp_directory_path() / "rtlab_image_file_test_good.exr";
    experiment::writeExr(image, good.string());
    EXPECT_NO_THROW(checkExrHeader(good.string()));
    EXPECT_EQ(experiment::readExrRgb(good.string()).pixels, image.pixels);

    const std::string bytes = readBytes(good);
    // A data window of 2^30 rows: refused by its size before any decoder allocates.
    const fs::path huge = writeBytes("huge.exr", setDataWindow(bytes, 4, (1 << 30) - 1));
    try {
        experiment::readExrRgb(huge.string());
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("larger than rtlab reads"), std::string::npos) << e.what();
    }
    // 40,000 rows in a file of a few hundred bytes: more chunks than the offset table can hold.
    const fs::path tall = writeBytes("tall.exr", setDataWindow(bytes, 4, 39999));
    try {
        checkExrHeader(tall.string());
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("do not fit"), std::string::npos) << e.what();
    }
    // A box2i whose size field says 80 bytes: OpenEXR reads 16 by the type, then parses the
    // rest of the header differently from this check (the fuzzer found a file whose next string
    // attribute then claimed 2 GB). Refused, naming the attribute.
    {
        std::string wide = bytes;
        const std::string key = std::string("dataWindow\0box2i\0", 17);
        const std::size_t at = wide.find(key);
        ASSERT_NE(at, std::string::npos);
        const std::int32_t size = 80;
        std::memcpy(wide.data() + at + key.size(), &size, sizeof size);
        try {
            experiment::readExrRgb(writeBytes("wide_box.exr", wide).string());
            FAIL() << "no error";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("'dataWindow' of type box2i has size 80, expected 16"),
                      std::string::npos)
                << e.what();
        }
    }
    // Cut inside the header, and not an EXR at all.
    EXPECT_THROW(checkExrHeader(writeBytes("cut.exr", bytes.substr(0, 40)).string()), Error);
    EXPECT_THROW(checkExrHeader(writeBytes("text.exr", "hello").string()), Error);
    EXPECT_THROW(checkExrHeader((fs::temp_directory_path() / "rtlab_no_such.exr").string()), Error);
}
