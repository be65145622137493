#include "test_scenes.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <utility>

namespace rtlab::reference::test {

std::uint32_t addMaterial(scene::RenderScene& scene, glm::vec3 albedo, glm::vec3 emission)
{
    scene::Material m;
    m.name = "material" + std::to_string(scene.materials.size());
    m.albedo = albedo;
    m.emission = emission;
    scene.materials.push_back(m);
    return std::uint32_t(scene.materials.size() - 1);
}

namespace {

void addTriangle(scene::RenderScene& scene, glm::vec3 a, glm::vec3 b, glm::vec3 c,
                 std::uint32_t material)
{
    const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    const auto base = std::uint32_t(scene.positions.size());
    for (const glm::vec3& p : {a, b, c}) {
        scene.positions.push_back(p);
        scene.normals.push_back(n);
    }
    scene.indices.insert(scene.indices.end(), {base, base + 1, base + 2});
    scene.triangleMaterial.push_back(material);
    scene.boundsMin = glm::min(glm::min(scene.boundsMin, a), glm::min(b, c));
    scene.boundsMax = glm::max(glm::max(scene.boundsMax, a), glm::max(b, c));
    if (scene.positions.size() == 3) {
        scene.boundsMin = glm::min(a, glm::min(b, c));
        scene.boundsMax = glm::max(a, glm::max(b, c));
    }
}

} // namespace

void addQuad(scene::RenderScene& scene, glm::vec3 corner, glm::vec3 u, glm::vec3 v,
             std::uint32_t material)
{
    addTriangle(scene, corner, corner + u, corner + u + v, material);
    addTriangle(scene, corner, corner + u + v, corner + v, material);
}

void addIcosphere(scene::RenderScene& scene, glm::vec3 centre, float radius, int subdivisions,
                  bool inward, std::uint32_t material)
{
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<glm::dvec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                 {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                 {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    for (auto& p : v)
        p = glm::normalize(p);
    std::vector<std::array<int, 3>> faces = {
        {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
        {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (int s = 0; s < subdivisions; ++s) {
        std::map<std::pair<int, int>, int> midpoints;
        auto midpoint = [&](int a, int b) {
            const auto key = std::minmax(a, b);
            if (auto it = midpoints.find(key); it != midpoints.end())
                return it->second;
            v.push_back(glm::normalize(v[a] + v[b]));
            return midpoints[key] = int(v.size() - 1);
        };
        std::vector<std::array<int, 3>> next;
        for (const auto& f : faces) {
            const int ab = midpoint(f[0], f[1]);
            const int bc = midpoint(f[1], f[2]);
            const int ca = midpoint(f[2], f[0]);
            next.push_back({f[0], ab, ca});
            next.push_back({f[1], bc, ab});
            next.push_back({f[2], ca, bc});
            next.push_back({ab, bc, ca});
        }
        faces = std::move(next);
    }
    for (const auto& f : faces) {
        const glm::vec3 a = centre + radius * glm::vec3(v[f[0]]);
        const glm::vec3 b = centre + radius * glm::vec3(v[f[1]]);
        const glm::vec3 c = centre + radius * glm::vec3(v[f[2]]);
        if (inward)
            addTriangle(scene, a, c, b, material);
        else
            addTriangle(scene, a, b, c, material);
    }
}

void addBox(scene::RenderScene& scene, glm::vec3 lo, glm::vec3 hi, std::uint32_t material)
{
    const glm::vec3 d = hi - lo;
    const glm::vec3 x(d.x, 0, 0), y(0, d.y, 0), z(0, 0, d.z);
    addQuad(scene, lo, z, y, material);     // -x
    addQuad(scene, lo + x, y, z, material); // +x
    addQuad(scene, lo, x, z, material);     // -y
    addQuad(scene, lo + y, z, x, material); // +y
    addQuad(scene, lo, y, x, material);     // -z
    addQuad(scene, lo + z, x, y, material); // +z
}

scene::GBuffer makePointGBuffer(int width, int height,
                                const std::function<bool(int, int, glm::vec3&, glm::vec3&)>& place,
                                glm::vec3 albedo, glm::vec3 emission)
{
    scene::GBuffer g;
    g.width = width;
    g.height = height;
    g.depth = Image<float>(width, height, 1.0f);
    g.position = Image<glm::vec3>(width, height, glm::vec3(0.0f));
    g.normal = Image<glm::vec3>(width, height, glm::vec3(0.0f));
    g.albedo = Image<glm::vec3>(width, height, glm::vec3(0.0f));
    g.emission = Image<glm::vec3>(width, height, glm::vec3(0.0f));
    g.materialId = Image<std::uint32_t>(width, height, scene::kNoMaterial);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            glm::vec3 p(0.0f), n(0.0f);
            if (!place(x, y, p, n))
                continue;
            g.position.at(x, y) = p;
            g.normal.at(x, y) = n;
            g.albedo.at(x, y) = albedo;
            g.emission.at(x, y) = emission;
            g.materialId.at(x, y) = 0;
        }
    }
    return g;
}

ReferenceSettings makeSettings(Quantity quantity)
{
    ReferenceSettings s;
    s.quantity = quantity;
    s.useCache = false;
    return s;
}

std::string makeTemporaryFolder(const std::string& name)
{
    std::random_device device;
    const auto path = std::filesystem::temp_directory_path() /
                      ("rtlab_reference_" + name + "_" + std::to_string(device()));
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
    return path.string();
}

scene::RenderScene makeRoomScene()
{
    scene::RenderScene room;
    const auto white = addMaterial(room, glm::vec3(0.7f));
    const auto red = addMaterial(room, glm::vec3(0.7f, 0.15f, 0.1f));
    const auto green = addMaterial(room, glm::vec3(0.15f, 0.6f, 0.1f));
    const auto lamp = addMaterial(room, glm::vec3(0.2f), glm::vec3(4.0f, 3.0f, 2.0f));
    addQuad(room, {-2, 0, -2}, {0, 0, 4}, {4, 0, 0}, white); // floor
    addQuad(room, {-2, 0, -2}, {4, 0, 0}, {0, 3, 0}, white); // back wall
    addQuad(room, {-2, 0, -2}, {0, 3, 0}, {0, 0, 4}, red);   // left wall
    addQuad(room, {2, 0, -2}, {0, 0, 4}, {0, 3, 0}, green);  // right wall
    addQuad(room, {-2, 0, 2}, {0, 3, 0}, {4, 0, 0}, white);  // front wall
    // Ceiling with a 1 x 1 opening in the middle.
    addQuad(room, {-2, 3, -2}, {4, 0, 0}, {0, 0, 1.5f}, white);
    addQuad(room, {-2, 3, 0.5f}, {4, 0, 0}, {0, 0, 1.5f}, white);
    addQuad(room, {-2, 3, -0.5f}, {1.5f, 0, 0}, {0, 0, 1}, white);
    addQuad(room, {0.5f, 3, -0.5f}, {1.5f, 0, 0}, {0, 0, 1}, white);
    addBox(room, {-0.8f, 0, -0.6f}, {0.2f, 1.2f, 0.4f}, white);
    addQuad(room, {-1.99f, 1, -0.5f}, {0, 0, 1}, {0, 1, 0}, lamp); // emissive patch
    room.pointLights.push_back({glm::vec3(1.0f, 2.5f, 1.0f), glm::vec3(5.0f)});
    room.sky.kind = scene::Sky::Kind::Srbf;
    room.sky.sharpness = 4.0f;
    for (int i = 0; i < scene::kConeDirectionCount; ++i)
        room.sky.lobes[i] =
            glm::vec3(0.5f + 0.1f * float(i % 4), 0.6f, 0.9f - 0.05f * float(i % 3));
    room.updateBounds();
    return room;
}

scene::GBuffer makeRoomGBuffer(const scene::RenderScene& room, int width, int height)
{
    scene::Camera camera;
    camera.position = glm::vec3(0.3f, 1.6f, 1.9f);
    camera.target = glm::vec3(-0.2f, 0.9f, -1.0f);
    camera.verticalFovDegrees = 70.0f;
    return castGBuffer(room, camera, width, height);
}

double computeGammaQ(double a, double x)
{
    // [Press et al., Numerical Recipes, 6.2]: series for x < a + 1, continued fraction beyond.
    if (x <= 0.0)
        return 1.0;
    const double lnGammaA = std::lgamma(a);
    if (x < a + 1.0) {
        double ap = a, sum = 1.0 / a, del = sum;
        for (int n = 0; n < 100000; ++n) {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if (std::abs(del) < std::abs(sum) * 1e-15)
                break;
        }
        return 1.0 - sum * std::exp(-x + a * std::log(x) - lnGammaA);
    }
    const double tiny = 1e-300;
    double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
    for (int i = 1; i < 100000; ++i) {
        const double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (std::abs(d) < tiny)
            d = tiny;
        c = b + an / c;
        if (std::abs(c) < tiny)
            c = tiny;
        d = 1.0 / d;
        const double del = d * c;
        h *= del;
        if (std::abs(del - 1.0) < 1e-15)
            break;
    }
    return std::exp(-x + a * std::log(x) - lnGammaA) * h;
}

void getGaussLegendre(int n, std::vector<double>& nodes, std::vector<double>& weights)
{
    nodes.assign(n, 0.0);
    weights.assign(n, 0.0);
    for (int i = 0; i < n; ++i) {
        double z = std::cos(M_PI * (i + 0.75) / (n + 0.5));
        double dp = 0.0;
        for (int iter = 0; iter < 100; ++iter) {
            double p0 = 1.0, p1 = z;
            for (int k = 2; k <= n; ++k) {
                const double pk = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = pk;
            }
            dp = n * (z * p1 - p0) / (z * z - 1.0);
            const double dz = p1 / dp;
            z -= dz;
            if (std::abs(dz) < 1e-16)
                break;
        }
        nodes[i] = z;
        weights[i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
}

double integrate(const std::function<double(double)>& f, double a, double b, int panels)
{
    static const std::pair<std::vector<double>, std::vector<double>> rule = [] {
        std::pair<std::vector<double>, std::vector<double>> r;
        getGaussLegendre(16, r.first, r.second);
        return r;
    }();
    const auto& [nodes, weights] = rule;
    double sum = 0.0;
    const double h = (b - a) / panels;
    for (int p = 0; p < panels; ++p) {
        const double lo = a + p * h;
        for (std::size_t i = 0; i < nodes.size(); ++i)
            sum += weights[i] * 0.5 * h * f(lo + 0.5 * h * (nodes[i] + 1.0));
    }
    return sum;
}

} // namespace rtlab::reference::test
