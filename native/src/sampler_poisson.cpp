// The poisson sampler: blue-noise (Poisson-disk) points per pixel.
//
// A good Poisson-disk set of exactly spp points costs far more to make than
// spp camera rays cost to trace (one pattern below: 0.26 ms at 64 spp, 4.7 ms
// at 1024 on one core; per pixel, about 50 times the trace), so the sets are
// made once per spp and reused: a pool of toroidal patterns, each the
// survivors of Yuksel's weighted sample elimination ("Sample Elimination for
// Generating Poisson Disk Sample Sets", Eurographics 2015) applied to 5 * spp
// (at least 256) uniform candidates drawn from fixed streams. Their minimum
// toroidal distance is 0.67-0.72 of the hexagonal-packing spacing.
//
// A pixel then draws, from its own stream, one pattern for the film and one
// for the lens, each under one of the 8 symmetries of the square and a uniform
// toroidal shift. Both keep toroidal distances, so every pixel's set has its
// pattern's minimum distance; the shift makes every point uniform on [0,1)^2,
// so pixel estimates stay unbiased. The lens points are shuffled per pixel, as
// for jittered, so film i and lens i are unrelated even when both draw the
// same pattern.
//
// The patterns are made lazily, one at a time on first use (any thread; the
// content depends only on spp and the pattern number), and kept for the life
// of the process.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "rng.h"
#include "samplers.h"

namespace lc {
namespace {

constexpr uint64_t kPoissonStream = 17;         // per-pixel choices, clear of the other samplers' streams
constexpr uint64_t kPatternSeed = 0x5eed0fb1;   // fixed: patterns are part of the sampler, not of the seed
constexpr int kCandidatesPerSample = 5;         // Yuksel's recommended input size...
constexpr int kMinCandidates = 256;             // ...but more for small spp, where 5x leaves poor sets
constexpr double kUnlimitedShare = 1e-3;        // see find_neighbours
constexpr int kMaxPoolSize = 64;
constexpr int64_t kPoolPointBudget = 1 << 18;   // points kept per spp, bounding memory (2 MB) for huge spp

double torus_distance(Point2f a, Point2f b) {
    double dx = std::fabs(double(a.x) - double(b.x)), dy = std::fabs(double(a.y) - double(b.y));
    dx = std::min(dx, 1.0 - dx);
    dy = std::min(dy, 1.0 - dy);
    return std::sqrt(dx * dx + dy * dy);
}

// Max-heap of candidate indices by weight (ties: larger index first) that can
// lower one entry's weight in place.
class EliminationHeap {
  public:
    explicit EliminationHeap(const std::vector<double>& weight)
        : weight_(weight), heap_(weight.size()), pos_(weight.size()) {
        for (size_t i = 0; i < heap_.size(); ++i) heap_[i] = int(i), pos_[i] = int(i);
        for (int i = int(heap_.size()) / 2 - 1; i >= 0; --i) sift_down(i);
    }

    int pop() {
        int top = heap_[0];
        move(int(heap_.size()) - 1, 0);
        heap_.pop_back();
        if (!heap_.empty()) sift_down(0);
        return top;
    }

    // Call after weight[i] decreased.
    void decreased(int i) { sift_down(pos_[size_t(i)]); }

  private:
    bool above(int a, int b) const {
        return weight_[size_t(a)] > weight_[size_t(b)] || (weight_[size_t(a)] == weight_[size_t(b)] && a > b);
    }
    void move(int from, int to) {
        heap_[size_t(to)] = heap_[size_t(from)];
        pos_[size_t(heap_[size_t(to)])] = to;
    }
    void sift_down(int at) {
        int n = int(heap_.size()), item = heap_[size_t(at)];
        for (;;) {
            int child = 2 * at + 1;
            if (child >= n) break;
            if (child + 1 < n && above(heap_[size_t(child + 1)], heap_[size_t(child)])) ++child;
            if (!above(heap_[size_t(child)], item)) break;
            move(child, at);
            at = child;
        }
        heap_[size_t(at)] = item;
        pos_[size_t(item)] = at;
    }

    const std::vector<double>& weight_;
    std::vector<int> heap_, pos_;
};

struct Neighbour {
    int index;
    float weight;  // what this neighbour adds to the candidate's weight
};

// For every candidate, the others within d_max on the torus and the weight
// each adds to it. A grid of cells no smaller than d_max: 3 x 3 cells suffice.
void find_neighbours(const std::vector<Point2f>& c, double d_max, double d_min, std::vector<int>& offset,
                     std::vector<Neighbour>& neighbours) {
    // Yuksel's weight: (1 - d / d_max)^8 with d limited below by d_min, plus a
    // small share of the unlimited weight. Alone, the limit makes every pair
    // closer than d_min weigh the same, and on small sets a near-coincident
    // pair can then outlast a well-spaced point: the worst minimum distance
    // over the patterns for spp 2..33 was 0.02 d_max, with the share 0.69 d_max.
    auto weight = [&](double d) {
        auto pow8 = [](double t) { t *= t; t *= t; return t * t; };
        return pow8(1.0 - std::max(d, d_min) / d_max) + kUnlimitedShare * pow8(1.0 - d / d_max);
    };
    const int m = int(c.size());
    offset.assign(size_t(m) + 1, 0);
    neighbours.clear();
    int g = int(std::floor(1.0 / d_max));
    if (g < 3) {  // few points: every pair
        for (int i = 0; i < m; ++i) {
            for (int j = 0; j < m; ++j) {
                double d = torus_distance(c[size_t(i)], c[size_t(j)]);
                if (j != i && d < d_max) neighbours.push_back({j, float(weight(d))});
            }
            offset[size_t(i) + 1] = int(neighbours.size());
        }
        return;
    }
    // Counting sort of the candidates into cells
    auto cell_of = [&](float v) { return std::min(int(v * float(g)), g - 1); };
    std::vector<int> cell_start(size_t(g) * size_t(g) + 1, 0), in_cell(static_cast<size_t>(m));
    for (const Point2f& p : c) ++cell_start[size_t(cell_of(p.y) * g + cell_of(p.x) + 1)];
    for (size_t k = 1; k < cell_start.size(); ++k) cell_start[k] += cell_start[k - 1];
    std::vector<int> fill(cell_start.begin(), cell_start.end() - 1);
    for (int i = 0; i < m; ++i) {
        int cell = cell_of(c[size_t(i)].y) * g + cell_of(c[size_t(i)].x);
        in_cell[size_t(fill[size_t(cell)]++)] = i;
    }
    // Neighbours from the 3 x 3 cells around each candidate, wrapping round
    for (int i = 0; i < m; ++i) {
        int cx = cell_of(c[size_t(i)].x), cy = cell_of(c[size_t(i)].y);
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                int cell = ((cy + dy + g) % g) * g + (cx + dx + g) % g;
                for (int k = cell_start[size_t(cell)]; k < cell_start[size_t(cell) + 1]; ++k) {
                    int j = in_cell[size_t(k)];
                    double d = torus_distance(c[size_t(i)], c[size_t(j)]);
                    if (j != i && d < d_max) neighbours.push_back({j, float(weight(d))});
                }
            }
        offset[size_t(i) + 1] = int(neighbours.size());
    }
}

// spp points of one pattern: Yuksel's weighted sample elimination on the torus.
std::vector<Point2f> make_pattern(int spp, int pattern) {
    // Candidates: uniform, from a fixed stream per (spp, pattern)
    const int m = std::max(kCandidatesPerSample * spp, kMinCandidates);
    Pcg32 rng(kPatternSeed, uint64_t(spp), uint64_t(pattern));
    std::vector<Point2f> candidates(static_cast<size_t>(m));
    for (Point2f& p : candidates) p = {rng.next_float(), rng.next_float()};

    // Radii (Yuksel 2015): d_max, the spacing of spp points in a hexagonal
    // packing of unit area; d_min, where weights stop growing.
    const double d_max = std::sqrt(2.0 / (std::sqrt(3.0) * spp));
    const double d_min = d_max * (1.0 - std::pow(double(spp) / m, 1.5)) * 0.65;
    std::vector<int> offset;
    std::vector<Neighbour> neighbours;
    find_neighbours(candidates, d_max, d_min, offset, neighbours);
    std::vector<double> weight(size_t(m), 0.0);
    for (int i = 0; i < m; ++i)
        for (int k = offset[size_t(i)]; k < offset[size_t(i) + 1]; ++k)
            weight[size_t(i)] += neighbours[size_t(k)].weight;

    // Remove the most crowded candidate, m - spp times, unburdening its neighbours
    EliminationHeap heap(weight);
    std::vector<bool> removed(size_t(m), false);
    for (int left = m; left > spp; --left) {
        int i = heap.pop();
        removed[size_t(i)] = true;
        for (int k = offset[size_t(i)]; k < offset[size_t(i) + 1]; ++k) {
            const Neighbour& n = neighbours[size_t(k)];
            if (removed[size_t(n.index)]) continue;
            weight[size_t(n.index)] -= n.weight;
            heap.decreased(n.index);
        }
    }
    std::vector<Point2f> points;
    points.reserve(size_t(spp));
    for (int i = 0; i < m; ++i)
        if (!removed[size_t(i)]) points.push_back(candidates[size_t(i)]);
    return points;
}

// The patterns for one spp, each made on first use.
class PatternPool {
  public:
    explicit PatternPool(int spp)
        : spp_(spp),
          size_(int(std::clamp<int64_t>(kPoolPointBudget / spp, 1, kMaxPoolSize))),
          slots_(new Slot[size_t(size_)]) {}

    int size() const { return size_; }

    const std::vector<Point2f>& pattern(int k) {
        Slot& slot = slots_[size_t(k)];
        std::call_once(slot.made, [&] { slot.points = make_pattern(spp_, k); });
        return slot.points;
    }

  private:
    struct Slot {
        std::once_flag made;
        std::vector<Point2f> points;
    };
    int spp_, size_;
    std::unique_ptr<Slot[]> slots_;
};

PatternPool& pool_for(int spp) {
    static std::mutex mutex;
    static std::map<int, std::unique_ptr<PatternPool>> pools;
    std::lock_guard<std::mutex> lock(mutex);
    std::unique_ptr<PatternPool>& pool = pools[spp];
    if (!pool) pool = std::make_unique<PatternPool>(spp);
    return *pool;
}

float wrap_unit(float v) {
    v -= std::floor(v);
    return below_one(v);  // v - floor(v) rounds to 1 for tiny negative v
}

// One pattern from the pool under a random square symmetry and toroidal shift.
void place_pattern(PatternPool& pool, Pcg32& rng, int spp, Point2f* out) {
    const std::vector<Point2f>& pattern = pool.pattern(int(rng.next_below(uint32_t(pool.size()))));
    uint32_t symmetry = rng.next_below(8);
    float shift_x = rng.next_float(), shift_y = rng.next_float();
    float sign_x = (symmetry & 2) ? -1.0f : 1.0f, sign_y = (symmetry & 4) ? -1.0f : 1.0f;
    for (int i = 0; i < spp; ++i) {
        Point2f p = pattern[size_t(i)];
        if (symmetry & 1) std::swap(p.x, p.y);
        out[i] = {wrap_unit(sign_x * p.x + shift_x), wrap_unit(sign_y * p.y + shift_y)};
    }
}

}  // namespace

void fill_poisson(uint64_t seed, uint64_t pixel_index, int spp, Point2f* film, Point2f* lens) {
    PatternPool& pool = pool_for(spp);
    Pcg32 rng(seed, pixel_index, kPoissonStream);
    place_pattern(pool, rng, spp, film);
    place_pattern(pool, rng, spp, lens);
    for (int i = spp - 1; i > 0; --i) std::swap(lens[i], lens[rng.next_below(uint32_t(i + 1))]);
}

// Every pattern of spp's pool made now, not on first use: a render can then
// time its samples without the one-time cost of making them (at 1024 spp the
// 64 patterns cost about 0.3 s, more than a small render).
void prepare_poisson_patterns(int spp) {
    if (spp < 1) return;
    PatternPool& pool = pool_for(spp);
    for (int k = 0; k < pool.size(); ++k) pool.pattern(k);
}

}  // namespace lc
