#include "packet_append.h"

#include <immintrin.h>

#include "shading_lanes.h"

namespace lc {

bool packet_append_available() {
    static const bool on = shading_kernel() == ShadingKernel::Avx512 && __builtin_cpu_supports("bmi2") &&
                           __builtin_cpu_supports("popcnt");
    return on;
}

uint32_t live_bits(const bool* alive) {
    static_assert(kPacketSize == 16, "one 16-byte compare");
    const __m128i flags = _mm_loadu_si128(reinterpret_cast<const __m128i*>(alive));
    return ~uint32_t(_mm_movemask_epi8(_mm_cmpeq_epi8(flags, _mm_setzero_si128()))) & 0xFFFFu;
}

namespace {

// prefix: take is the run's first `taken` rows, which need no compress (a
// slow instruction on Zen 4: 9 compresses cost more than the 9 masked stores).
[[gnu::target("avx512f")]] inline void append_floats(const float* from, __mmask16 take, int taken, bool prefix,
                                                     float* to) {
    const __m512 row = _mm512_loadu_ps(from);
    const __m512 v = prefix ? row : _mm512_maskz_compress_ps(take, row);
    _mm512_mask_storeu_ps(to, __mmask16((1u << taken) - 1u), v);
}

}  // namespace

[[gnu::target("avx512f,bmi2,popcnt")]] void append_live_rows(const CameraRayRows& rows, int at, const float* time_u,
                                                 const float* weight, const size_t* slot, uint32_t* live,
                                                 RayBatch* batch, float* batch_weight, size_t* batch_slot) {
    const int count = batch->count;
    // The lowest (room) of the live bits: one deposit (a loop clearing the
    // highest bit until they fit was a third of this function, perf).
    const uint32_t take = _pdep_u32((uint32_t(1) << (kPacketSize - count)) - 1u, *live);
    const int taken = __builtin_popcount(take);
    const __mmask16 mask = __mmask16(take);
    const bool prefix = take == (uint32_t(1) << taken) - 1u;  // most runs: every ray alive, or the rows that fit
    for (int a = 0; a < 3; ++a) {
        append_floats(rows.origin[a] + at, mask, taken, prefix, batch->origin[a] + count);
        append_floats(rows.direction[a] + at, mask, taken, prefix, batch->direction[a] + count);
    }
    append_floats(time_u + at, mask, taken, prefix, batch->time + count);
    if (weight) append_floats(weight + at, mask, taken, prefix, batch_weight + count);
    else _mm512_mask_storeu_ps(batch_weight + count, __mmask16((1u << taken) - 1u), _mm512_set1_ps(1.0f));
    // The slots, 8 bytes each: two halves of eight.
    static_assert(sizeof(size_t) == 8, "64-bit slots");
    const __mmask8 low = __mmask8(take & 0xFFu), high = __mmask8(take >> 8);
    const int low_taken = __builtin_popcount(take & 0xFFu), high_taken = taken - low_taken;
    const __m512i low_row = _mm512_loadu_si512(slot + at), high_row = _mm512_loadu_si512(slot + at + 8);
    const __m512i low_slots = prefix ? low_row : _mm512_maskz_compress_epi64(low, low_row);
    const __m512i high_slots = prefix ? high_row : _mm512_maskz_compress_epi64(high, high_row);
    _mm512_mask_storeu_epi64(batch_slot + count, __mmask8((1u << low_taken) - 1u), low_slots);
    _mm512_mask_storeu_epi64(batch_slot + count + low_taken, __mmask8((1u << high_taken) - 1u), high_slots);
    batch->count = count + taken;
    *live &= ~take;
}

}  // namespace lc
