#pragma once
/// @file shard_part.h
/// A simulation split over a cluster. Particles never act on each other, so
/// a cloud's particles can move in shards, each on its own machine, through
/// the same fields and past the same moving objects:
///   1. the objects' part moves the dynamic objects alone, once, into
///      OUT/shards/objects/ (field.vdb, tracks.json, stats.json);
///   2. shard i of K (0 <= i < K) advects the particles whose id % K == i,
///      the objects replayed from that part's tracks, into
///      OUT/shards/i-of-K/: per frame particles.####.vdb, every attribute at
///      full precision, with what the simulator keeps per particle
///      (makeParticleGrid withState);
///   3. the merge (shard_merge.h) writes into OUT, per frame, the
///      density.####.vdb and particles.####.vdb a single run writes.
/// Each part is a run of simulateScene (SimulateOptions::part): it resumes as
/// any run does, after its own last complete frame.

#include <cstdint>
#include <string>

namespace vfield {

struct ShardPart {
    int index = 0; ///< 0 .. count - 1, as Slurm numbers array tasks
    int count = 0; ///< shards in all; 0: the objects' part

    static ShardPart objects() { return {}; }
    /// "objects", or "I/K" with 0 <= I < K. Throws ValueError.
    static ShardPart parse(const std::string& text);

    bool isObjects() const { return count == 0; }
    /// Whether the particle of this id is this shard's (none is the objects' part's).
    bool holds(uint32_t id) const { return count > 0 && id % uint32_t(count) == uint32_t(index); }
    /// "objects" or "3/8", as parse takes it.
    std::string text() const;
    /// Its folder in OUT: OUT/shards/objects or OUT/shards/3-of-8.
    std::string folder(const std::string& out) const;
    /// The part's inputs hash, from the whole simulation's (inputs_hash.h):
    /// no part's frames pass for another's.
    uint64_t inputsHash(uint64_t simulation) const;
};

} // namespace vfield
