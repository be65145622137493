// Wavefront OBJ and MTL reading with line and column in every error. Numbers are parsed strictly
// (a coordinate such as "nan" or "1e39" is reported, not read as 0 or infinity).

#include "scene/mesh_loader.h"

#include "core/error.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <optional>
#include <string_view>
#include <unordered_map>
#include <unordered_set>

namespace rtlab::scene::detail {

namespace {

constexpr std::string_view kSpaces = " \t\r\f\v";

//! One statement: a line without its comment, split into whitespace-separated tokens.
class Statement {
public:
    Statement(std::string_view line, int number) : mLine(line), mNumber(number)
    {
        const std::size_t hash = line.find('#');
        std::string_view rest = line.substr(0, hash);
        while (true) {
            const std::size_t begin = rest.find_first_not_of(kSpaces);
            if (begin == std::string_view::npos)
                break;
            rest.remove_prefix(begin);
            const std::size_t end = std::min(rest.find_first_of(kSpaces), rest.size());
            mTokens.push_back(rest.substr(0, end));
            rest.remove_prefix(end);
        }
    }

    bool isEmpty() const { return mTokens.empty(); }
    std::size_t size() const { return mTokens.size(); }
    std::string_view operator[](std::size_t i) const { return mTokens[i]; }
    //! Everything after the keyword, trimmed (names may contain spaces).
    std::string_view getRest() const
    {
        if (mTokens.size() < 2)
            return {};
        const std::string_view last = mTokens.back();
        return std::string_view(
            mTokens[1].data(),
            static_cast<std::size_t>(last.data() + last.size() - mTokens[1].data()));
    }
    //! The location of token `i` (or of the line when `i` is past the end) in `file`.
    SourceLocation locate(const std::string& file, std::size_t i) const
    {
        if (i >= mTokens.size())
            return {file, mNumber, static_cast<int>(mLine.size()) + 1};
        return {file, mNumber, static_cast<int>(mTokens[i].data() - mLine.data()) + 1};
    }

private:
    std::string_view mLine;
    int mNumber;
    std::vector<std::string_view> mTokens;
};

//! Calls `visit(line, number)` for every line of `text` (1-based numbers).
template <typename Visit> void forEachLine(std::string_view text, Visit&& visit)
{
    int number = 0;
    while (!text.empty()) {
        const std::size_t end = std::min(text.find('\n'), text.size());
        visit(text.substr(0, end), ++number);
        text.remove_prefix(std::min(end + 1, text.size()));
    }
}

//! The token as a double; nullopt when it is not a number. NaN and infinities are returned as
//! such, and so are values beyond double range (as infinity or zero).
std::optional<double> parseNumber(std::string_view token)
{
    if (token.size() > 1 && token[0] == '+' && token[1] != '-')
        token.remove_prefix(1);
    double value = 0.0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (end != token.data() + token.size())
        return std::nullopt;
    if (ec == std::errc::result_out_of_range)
        return std::strtod(std::string(token).c_str(), nullptr);
    if (ec != std::errc())
        return std::nullopt;
    return value;
}

std::optional<long long> parseInteger(std::string_view token)
{
    long long value = 0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || end != token.data() + token.size())
        return std::nullopt;
    return value;
}

std::string quote(std::string_view s)
{
    return "'" + std::string(s) + "'";
}

//! A finite single-precision value of token `i` of `statement`, or an InputError saying that
//! `what` has a bad `component` ("coordinate", "component").
float readFiniteFloat(const std::string& file, const Statement& statement, std::size_t i,
                      const std::string& what, const char* component)
{
    const std::optional<double> value = parseNumber(statement[i]);
    if (!value)
        throw InputError(statement.locate(file, i),
                         "expected a number for " + what + ", found " + quote(statement[i]));
    const auto single = static_cast<float>(*value);
    if (!std::isfinite(*value) || !std::isfinite(single))
        throw InputError(statement.locate(file, i),
                         what + " has a non-finite " + component + " " + quote(statement[i]) +
                             (std::isfinite(*value) ? " (beyond single precision)" : ""));
    return single;
}

struct MtlDefinition {
    glm::vec3 albedo{0.8f};
    glm::vec3 emission{0.0f};
    SourceLocation where;
};

//! Reads an RGB statement (`Kd r [g b]`, `Ke r g b`); a single value stands for grey.
glm::vec3 readRgb(const std::string& file, const Statement& statement, const std::string& what)
{
    if (statement.size() < 2)
        throw InputError(statement.locate(file, 1), what + " needs an RGB colour");
    if (!parseNumber(statement[1]))
        throw InputError(statement.locate(file, 1),
                         what + ": only RGB colours are supported, found " + quote(statement[1]));
    if (statement.size() != 2 && statement.size() != 4)
        throw InputError(statement.locate(file, std::min<std::size_t>(statement.size(), 4)),
                         what + " needs 1 or 3 numbers, found " +
                             std::to_string(statement.size() - 1));
    glm::vec3 rgb;
    for (int c = 0; c < 3; ++c)
        rgb[c] =
            readFiniteFloat(file, statement, statement.size() == 2 ? 1 : 1 + c, what, "component");
    return rgb;
}

void readMtl(const std::string& file, std::string_view text,
             std::unordered_map<std::string, MtlDefinition>& definitions)
{
    MtlDefinition* current = nullptr;
    std::string currentName;
    forEachLine(text, [&](std::string_view line, int number) {
        const Statement statement(line, number);
        if (statement.isEmpty())
            return;
        const std::string_view keyword = statement[0];
        if (keyword == "newmtl") {
            currentName = std::string(statement.getRest());
            if (currentName.empty())
                throw InputError(statement.locate(file, 1), "newmtl needs a material name");
            const auto [it, inserted] = definitions.try_emplace(currentName);
            if (!inserted)
                throw InputError(statement.locate(file, 1), "material " + quote(currentName) +
                                                                " is defined twice (first at " +
                                                                it->second.where.toString() + ")");
            it->second.where = statement.locate(file, 1);
            current = &it->second;
        } else if (keyword == "Kd" || keyword == "Ke") {
            if (!current)
                throw InputError(statement.locate(file, 0),
                                 std::string(keyword) + " before any newmtl");
            const std::string what = std::string(keyword) + " of material " + quote(currentName);
            (keyword == "Kd" ? current->albedo : current->emission) =
                readRgb(file, statement, what);
        }
    });
}

//! Parses one OBJ file into a RawMesh.
class ObjReader {
public:
    ObjReader(const std::string& path, const MeshLoadOptions& options)
        : mPath(path), mOptions(options)
    {
        mRaw.materials.push_back({}); // kNoMaterial: faces before any usemtl
        mFirstUse.emplace_back();
    }

    RawMesh read(std::string_view text)
    {
        forEachLine(text, [&](std::string_view line, int number) {
            const Statement statement(line, number);
            if (!statement.isEmpty())
                readStatement(statement);
        });
        checkForwardReferences();
        resolveMaterials();
        return std::move(mRaw);
    }

private:
    enum class IndexKind { Position, TexCoord, Normal };

    //! A positive index beyond the elements defined so far; valid if they are defined later.
    struct ForwardReference {
        SourceLocation where;
        IndexKind kind;
        long long index; //!< as written (1-based)
        std::string face;
    };

    void readStatement(const Statement& s)
    {
        const std::string_view keyword = s[0];
        if (keyword == "v")
            readVertex(s);
        else if (keyword == "vn")
            readNormal(s);
        else if (keyword == "vt")
            ++mTexCoordCount;
        else if (keyword == "f")
            readFace(s);
        else if (keyword == "o" || keyword == "g") {
            mGroup = s.size() > 1
                         ? std::string(keyword == "o" ? "object " : "group ") + quote(s.getRest())
                         : std::string();
            mFaceInGroup = 0;
        } else if (keyword == "s")
            readSmoothingGroup(s);
        else if (keyword == "usemtl")
            readUseMaterial(s);
        else if (keyword == "mtllib")
            readMaterialLibraries(s);
    }

    void readVertex(const Statement& s)
    {
        const std::string what = "vertex " + std::to_string(mRaw.positions.size() + 1);
        if (s.size() < 4)
            throw InputError(s.locate(mPath, s.size()), what + " needs 3 coordinates");
        if (mRaw.positions.size() >= std::numeric_limits<std::uint32_t>::max())
            throw InputError(s.locate(mPath, 0), "too many vertices");
        glm::vec3 p;
        for (int c = 0; c < 3; ++c)
            p[c] = readFiniteFloat(mPath, s, 1 + c, what, "coordinate");
        mRaw.positions.push_back(p);
    }

    void readNormal(const Statement& s)
    {
        const std::string what = "normal " + std::to_string(mRaw.normals.size() + 1);
        if (s.size() < 4)
            throw InputError(s.locate(mPath, s.size()), what + " needs 3 coordinates");
        glm::vec3 n;
        for (int c = 0; c < 3; ++c)
            n[c] = readFiniteFloat(mPath, s, 1 + c, what, "coordinate");
        mRaw.normals.push_back(n);
    }

    std::string describeFace() const
    {
        std::string face = "face " + std::to_string(mFaceInGroup);
        return mGroup.empty() ? face : face + " of " + mGroup;
    }

    static std::string describeKind(IndexKind kind)
    {
        switch (kind) {
        case IndexKind::Position:
            return "vertex";
        case IndexKind::TexCoord:
            return "texture coordinate";
        case IndexKind::Normal:
            return "normal";
        }
        return {};
    }

    std::size_t countOf(IndexKind kind) const
    {
        switch (kind) {
        case IndexKind::Position:
            return mRaw.positions.size();
        case IndexKind::TexCoord:
            return mTexCoordCount;
        case IndexKind::Normal:
            return mRaw.normals.size();
        }
        return 0;
    }

    std::string describeOutOfRange(IndexKind kind, long long index, const std::string& face,
                                   bool atEnd) const
    {
        const std::size_t count = countOf(kind);
        const std::string plural =
            kind == IndexKind::Position ? "vertices" : describeKind(kind) + "s";
        return describeKind(kind) + " index " + std::to_string(index) + " in " + face +
               " is out of range: the file has " + std::to_string(count) + " " +
               (count == 1 ? describeKind(kind) : plural) + (atEnd ? "" : " before this line");
    }

    //! Resolves an OBJ index (1-based, or negative relative to the elements so far) to 0-based.
    std::int64_t resolveIndex(const Statement& s, std::size_t token, std::string_view text,
                              IndexKind kind)
    {
        const std::optional<long long> index = parseInteger(text);
        if (!index)
            throw InputError(s.locate(mPath, token), "malformed " + describeKind(kind) + " index " +
                                                         quote(text) + " in " + describeFace());
        if (*index == 0)
            throw InputError(s.locate(mPath, token), describeKind(kind) + " index 0 in " +
                                                         describeFace() +
                                                         " is invalid: OBJ indices start at 1");
        const auto count = static_cast<long long>(countOf(kind));
        if (*index < 0) {
            if (count + *index < 0)
                throw InputError(s.locate(mPath, token),
                                 describeOutOfRange(kind, *index, describeFace(), false));
            return count + *index;
        }
        if (*index > count)
            mForwardReferences.push_back({s.locate(mPath, token), kind, *index, describeFace()});
        return *index - 1;
    }

    void readFace(const Statement& s)
    {
        ++mFaceInGroup;
        if (s.size() < 4)
            throw InputError(s.locate(mPath, 0), describeFace() + " has " +
                                                     std::to_string(s.size() - 1) +
                                                     " corners; a face needs at least 3");
        std::vector<std::uint32_t> positions;
        std::vector<std::int64_t> normals;
        for (std::size_t i = 1; i < s.size(); ++i) {
            // v, v/vt, v//vn or v/vt/vn
            std::string_view fields[3];
            std::string_view rest = s[i];
            int fieldCount = 0;
            while (fieldCount < 3) {
                const std::size_t slash = rest.find('/');
                fields[fieldCount++] = rest.substr(0, slash);
                if (slash == std::string_view::npos)
                    break;
                rest.remove_prefix(slash + 1);
                if (fieldCount == 3)
                    throw InputError(s.locate(mPath, i),
                                     "malformed corner " + quote(s[i]) + " in " + describeFace());
            }
            positions.push_back(
                static_cast<std::uint32_t>(resolveIndex(s, i, fields[0], IndexKind::Position)));
            if (fieldCount > 1 && !fields[1].empty())
                resolveIndex(s, i, fields[1], IndexKind::TexCoord);
            normals.push_back(fieldCount > 2 ? resolveIndex(s, i, fields[2], IndexKind::Normal)
                                             : -1);
        }
        // Fan from the first corner.
        for (std::size_t i = 1; i + 1 < positions.size(); ++i) {
            for (std::size_t c : {std::size_t(0), i, i + 1}) {
                mRaw.cornerPosition.push_back(positions[c]);
                mRaw.cornerNormal.push_back(normals[c]);
            }
            mRaw.triangleMaterial.push_back(mMaterial);
            if (mHasSmoothing)
                mRaw.triangleSmoothing.push_back(mSmoothing);
        }
    }

    //! `s N` (N > 0: smoothing group N), `s 0` or `s off` (flat).
    void readSmoothingGroup(const Statement& s)
    {
        if (s.size() != 2)
            throw InputError(s.locate(mPath, 0),
                             "s needs one smoothing group: a number, or 'off'");
        const std::string_view g = s[1];
        std::uint32_t group = 0;
        if (g != "off") {
            const auto [end, error] = std::from_chars(g.data(), g.data() + g.size(), group);
            if (error != std::errc() || end != g.data() + g.size())
                throw InputError(s.locate(mPath, 1), "smoothing group " + quote(g) +
                                                         ": expected a number >= 0 or 'off'");
        }
        if (!mHasSmoothing) {
            // Triangles before the first `s` are in no group.
            mRaw.triangleSmoothing.assign(mRaw.triangleMaterial.size(), 0u);
            mHasSmoothing = true;
        }
        mSmoothing = group;
    }

    void readUseMaterial(const Statement& s)
    {
        const std::string name(s.getRest());
        if (name.empty())
            throw InputError(s.locate(mPath, 1), "usemtl needs a material name");
        const auto [it, inserted] =
            mMaterialIndex.try_emplace(name, static_cast<std::uint32_t>(mRaw.materials.size()));
        if (inserted) {
            mRaw.materials.push_back({name});
            mFirstUse.push_back(s.locate(mPath, 1));
        }
        mMaterial = it->second;
    }

    void readMaterialLibraries(const Statement& s)
    {
        if (s.size() < 2)
            throw InputError(s.locate(mPath, 1), "mtllib needs a file name");
        const std::filesystem::path directory = std::filesystem::path(mPath).parent_path();
        for (std::size_t i = 1; i < s.size(); ++i) {
            const std::string library = (directory / std::string(s[i])).string();
            if (!mLibraries.insert(library).second)
                continue;
            std::string text;
            try {
                text = readWholeFile(library);
            } catch (const InputError& e) {
                if (mOptions.materialsOptional) {
                    mRaw.warnings.push_back(s.locate(mPath, i).toString() + ": material library " +
                                            quote(s[i]) + ": " + e.message() +
                                            "; its materials default to albedo 0.8, no emission "
                                            "(the scene assigns the mesh's material anyway)");
                    continue;
                }
                throw InputError(s.locate(mPath, i), "material library " + quote(s[i]) + ": " +
                                                         e.location().toString() + ": " +
                                                         e.message());
            }
            readMtl(library, text, mDefinitions);
        }
    }

    void checkForwardReferences() const
    {
        for (const ForwardReference& r : mForwardReferences)
            if (r.index > static_cast<long long>(countOf(r.kind)))
                throw InputError(r.where, describeOutOfRange(r.kind, r.index, r.face, true));
    }

    void resolveMaterials()
    {
        for (std::size_t m = 0; m < mRaw.materials.size(); ++m) {
            RawMaterial& material = mRaw.materials[m];
            if (m == kNoMaterial)
                continue;
            const auto it = mDefinitions.find(material.name);
            if (it == mDefinitions.end() && mOptions.materialsOptional) {
                mRaw.warnings.push_back(mFirstUse[m].toString() + ": material " +
                                        quote(material.name) + " is not defined" +
                                        (mLibraries.empty() ? std::string(" (the file has no mtllib)")
                                                            : " in any mtllib") +
                                        "; it defaults to albedo 0.8, no emission (the scene "
                                        "assigns the mesh's material anyway)");
                continue;
            }
            if (it == mDefinitions.end())
                throw InputError(mFirstUse[m],
                                 "material " + quote(material.name) + " is not defined" +
                                     (mLibraries.empty() ? std::string(" (the file has no mtllib)")
                                                         : " in any mtllib"));
            material.albedo = it->second.albedo;
            material.emission = it->second.emission;
        }
    }

    static constexpr std::uint32_t kNoMaterial = 0;

    const std::string& mPath;
    const MeshLoadOptions& mOptions;
    RawMesh mRaw;
    std::uint32_t mMaterial = kNoMaterial;
    bool mHasSmoothing = false;  // some `s` statement was read
    std::uint32_t mSmoothing = 0; // the current smoothing group, 0 = off
    std::unordered_map<std::string, std::uint32_t> mMaterialIndex;
    std::vector<SourceLocation> mFirstUse; //!< per raw material, its first usemtl
    std::unordered_map<std::string, MtlDefinition> mDefinitions;
    std::unordered_set<std::string> mLibraries;
    std::size_t mTexCoordCount = 0;
    std::string mGroup;
    std::size_t mFaceInGroup = 0;
    std::vector<ForwardReference> mForwardReferences;
};

} // namespace

RawMesh readObj(const std::string& path, const std::string& text, const MeshLoadOptions& options)
{
    return ObjReader(path, options).read(text);
}

} // namespace rtlab::scene::detail
