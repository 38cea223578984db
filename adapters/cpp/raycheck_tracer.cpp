// A tracer for raycheck in one C++17 file: reads the mesh and the rays file,
// asks a tracer, writes the hits file (layouts: docs/exchange.md).
//
//     g++ -std=c++17 -O2 -pthread raycheck_tracer.cpp -o raycheck_tracer
//     ./raycheck_tracer MESH.ply RAYS HITS
//
// `Tracer` below is the part to replace with your own: it is built once over
// the mesh and asked one ray at a time, from several threads. This one tests
// every triangle (brute force) with the Moller-Trumbore test in double
// precision (Moller & Trumbore 1997, "Fast, Minimum Storage Ray/Triangle
// Intersection"), accepting u, v >= 0, u + v <= 1 and tnear <= t <= tfar.
// Exit codes: 0 written, 2 a bad file (one line on stderr names it and what
// is wrong).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

struct Vec3 {
    float x, y, z;
};

// The mesh as `raycheck rays --mesh-out` writes it: face i is primID i.
struct Mesh {
    std::vector<Vec3> vertices;
    std::vector<uint32_t> indices;  // three per triangle
    size_t triangles() const { return indices.size() / 3; }
};

// A ray as in the rays file (Embree's RTCRay): a hit counts for tnear <= t <= tfar.
struct Ray {
    Vec3 origin;
    float tnear;
    Vec3 dir;
    float tfar;
};

constexpr uint32_t kMiss = 0xFFFFFFFFu;

// A closest hit: u weights the triangle's second corner, v its third.
struct Hit {
    float t = 0, u = 0, v = 0;
    uint32_t prim = kMiss;
};

// ---- Your tracer goes here ------------------------------------------------
// Keep the two queries' meaning: `closest` returns the hit of smallest t in
// [tnear, tfar] (prim kMiss when there is none), `occluded` whether there is
// any. Both are called concurrently from several threads.
class Tracer {
  public:
    explicit Tracer(const Mesh &mesh) : mesh_(mesh) {}

    Hit closest(const Ray &ray) const {
        Hit best;
        double best_t = INFINITY;
        for (uint32_t prim = 0; prim < mesh_.triangles(); ++prim) {
            double t, u, v;
            if (intersect(ray, prim, t, u, v) && t < best_t) {
                best_t = t;
                best = Hit{float(t), float(u), float(v), prim};
            }
        }
        return best;
    }

    bool occluded(const Ray &ray) const {
        double t, u, v;
        for (uint32_t prim = 0; prim < mesh_.triangles(); ++prim) {
            if (intersect(ray, prim, t, u, v)) return true;
        }
        return false;
    }

  private:
    // Moller-Trumbore in double; every comparison is written so that a NaN
    // (from a NaN or infinite input) rejects the triangle.
    bool intersect(const Ray &ray, uint32_t prim, double &t, double &u, double &v) const {
        const Vec3 &a = mesh_.vertices[mesh_.indices[3 * prim]];
        const Vec3 &b = mesh_.vertices[mesh_.indices[3 * prim + 1]];
        const Vec3 &c = mesh_.vertices[mesh_.indices[3 * prim + 2]];
        const double e1[3] = {double(b.x) - a.x, double(b.y) - a.y, double(b.z) - a.z};
        const double e2[3] = {double(c.x) - a.x, double(c.y) - a.y, double(c.z) - a.z};
        const double d[3] = {ray.dir.x, ray.dir.y, ray.dir.z};
        const double p[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2],
                             d[0] * e2[1] - d[1] * e2[0]};
        const double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
        if (det == 0.0) return false;
        const double s[3] = {double(ray.origin.x) - a.x, double(ray.origin.y) - a.y,
                             double(ray.origin.z) - a.z};
        u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det;
        if (!(u >= 0.0 && u <= 1.0)) return false;
        const double q[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2],
                             s[0] * e1[1] - s[1] * e1[0]};
        v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
        if (!(v >= 0.0 && u + v <= 1.0)) return false;
        t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
        return ray.tnear <= t && t <= ray.tfar;
    }

    const Mesh &mesh_;
};
// ---- End of your tracer ---------------------------------------------------

// A file that is not what it should be.
struct BadFile : std::runtime_error {
    BadFile(const std::string &path, const std::string &what) : std::runtime_error(path + ": " + what) {}
};

static std::string read_file(const std::string &path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw BadFile(path, std::string("cannot be read (") + std::strerror(errno) + ")");
    return std::string(std::istreambuf_iterator<char>(in), {});
}

template <typename T>
static T load(const std::string &bytes, size_t at) {
    T value;
    std::memcpy(&value, bytes.data() + at, sizeof(T));  // the files are little-endian, like x86 and ARM
    return value;
}

// The binary little-endian PLY that `raycheck rays --mesh-out` writes, and no other.
static Mesh read_mesh(const std::string &path) {
    const std::string bytes = read_file(path);
    const std::string end_marker = "end_header\n";
    const size_t end = bytes.find(end_marker);
    if (bytes.compare(0, 4, "ply\n") != 0 || end == std::string::npos)
        throw BadFile(path, "not a PLY file (no `ply` line or no `end_header`)");
    std::istringstream header(bytes.substr(0, end));
    std::string line, layout;
    size_t vertices = 0, faces = 0;
    for (int number = 1; std::getline(header, line); ++number) {
        if (number == 1 || line.rfind("comment", 0) == 0 || line.rfind("obj_info", 0) == 0) continue;
        std::istringstream words(line);
        std::string first, name;
        words >> first;
        if (first == "element") {
            size_t count = 0;
            if (!(words >> name >> count)) throw BadFile(path, "line " + std::to_string(number) + ": expected `element NAME COUNT`");
            (name == "vertex" ? vertices : faces) = count;
            line = "element " + name;
        }
        layout += line + "; ";
    }
    const std::string expected =
        "format binary_little_endian 1.0; element vertex; property float x; property float y; "
        "property float z; element face; property list uchar uint vertex_indices; ";
    if (layout != expected)
        throw BadFile(path, "expected exactly the layout `raycheck rays --mesh-out` writes (" + expected + "), found " + layout);
    const size_t body = end + end_marker.size();
    const size_t need = 12 * vertices + 13 * faces;
    if (bytes.size() - body != need)
        throw BadFile(path, std::to_string(vertices) + " vertices and " + std::to_string(faces) + " triangles need " +
                                std::to_string(need) + " bytes after the header, found " + std::to_string(bytes.size() - body));
    Mesh mesh;
    mesh.vertices.resize(vertices);
    std::memcpy(mesh.vertices.data(), bytes.data() + body, 12 * vertices);
    mesh.indices.resize(3 * faces);
    for (size_t i = 0; i < faces; ++i) {
        const size_t at = body + 12 * vertices + 13 * i;
        if (uint8_t(bytes[at]) != 3)
            throw BadFile(path, "face " + std::to_string(i) + " has " + std::to_string(uint8_t(bytes[at])) + " corners; every face must be a triangle");
        for (size_t k = 0; k < 3; ++k) {
            const uint32_t index = load<uint32_t>(bytes, at + 1 + 4 * k);
            if (index >= vertices)
                throw BadFile(path, "face " + std::to_string(i) + " refers to vertex " + std::to_string(index) + ", but there are " + std::to_string(vertices));
            mesh.indices[3 * i + k] = index;
        }
    }
    return mesh;
}

// Sets 2 (shadow) and 6 (a stability case's any-hit rays) ask any hit;
// 1, 3, 4 and 5 ask closest hits.
static bool asks_any_hit(uint32_t set) { return set == 2 || set == 6; }

struct Rays {
    uint32_t set;
    std::vector<Ray> rays;
};

static Rays read_rays(const std::string &path) {
    const std::string bytes = read_file(path);
    if (bytes.size() < 32) throw BadFile(path, "truncated: " + std::to_string(bytes.size()) + " bytes, shorter than the 32-byte header");
    if (bytes.compare(0, 8, std::string("RCRAYS\0\0", 8)) != 0) throw BadFile(path, "not a raycheck rays file (no RCRAYS magic)");
    if (load<uint32_t>(bytes, 8) != 1) throw BadFile(path, "version " + std::to_string(load<uint32_t>(bytes, 8)) + " is not supported (this tracer reads version 1)");
    Rays rays{load<uint32_t>(bytes, 12), {}};
    if (rays.set < 1 || rays.set > 6) throw BadFile(path, "unknown ray set code " + std::to_string(rays.set) + " (this tracer knows 1 to 6)");
    const uint64_t count = load<uint64_t>(bytes, 16);
    if (count > (bytes.size() - 32) / 32 || (bytes.size() - 32) != count * 32)
        throw BadFile(path, "the header says " + std::to_string(count) + " rays of 32 bytes, the body has " + std::to_string(bytes.size() - 32) + " bytes");
    rays.rays.resize(count);
    std::memcpy(rays.rays.data(), bytes.data() + 32, 32 * count);
    return rays;
}

static void write_hits(const std::string &path, const Rays &rays, const std::vector<Hit> &hits, const std::vector<uint8_t> &occluded) {
    const bool any_hit = asks_any_hit(rays.set);
    std::string bytes("RCHITS\0\0", 8);
    const uint32_t version = 1, flags = any_hit ? 0 : 1, reserved = 0;  // flag bit 0: u, v are given
    const uint64_t count = rays.rays.size();
    bytes.append(reinterpret_cast<const char *>(&version), 4);
    bytes.append(reinterpret_cast<const char *>(&rays.set), 4);
    bytes.append(reinterpret_cast<const char *>(&count), 8);
    bytes.append(reinterpret_cast<const char *>(&flags), 4);
    bytes.append(reinterpret_cast<const char *>(&reserved), 4);
    if (any_hit)
        bytes.append(reinterpret_cast<const char *>(occluded.data()), occluded.size());
    else
        bytes.append(reinterpret_cast<const char *>(hits.data()), sizeof(Hit) * hits.size());
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    if (!out) throw BadFile(path, std::string("cannot be written (") + std::strerror(errno) + ")");
}

int main(int argc, char **argv) {
    if (argc != 4) {
        std::cerr << "usage: " << argv[0] << " MESH.ply RAYS HITS\n";
        return 2;
    }
    static_assert(sizeof(Ray) == 32 && sizeof(Hit) == 16, "records as in the files");
    try {
        const Mesh mesh = read_mesh(argv[1]);
        const Rays rays = read_rays(argv[2]);
        const Tracer tracer(mesh);
        const size_t count = rays.rays.size();
        std::vector<Hit> hits(asks_any_hit(rays.set) ? 0 : count);
        std::vector<uint8_t> occluded(asks_any_hit(rays.set) ? count : 0);
        // Each thread answers every n-th ray: each answer depends on its ray alone.
        const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
        std::vector<std::thread> workers;
        for (unsigned w = 0; w < threads; ++w) {
            workers.emplace_back([&, w] {
                for (size_t i = w; i < count; i += threads) {
                    if (asks_any_hit(rays.set))
                        occluded[i] = tracer.occluded(rays.rays[i]);
                    else
                        hits[i] = tracer.closest(rays.rays[i]);
                }
            });
        }
        for (auto &worker : workers) worker.join();
        write_hits(argv[3], rays, hits, occluded);
    } catch (const BadFile &e) {
        std::cerr << "raycheck_tracer: " << e.what() << "\n";
        return 2;
    }
    return 0;
}
