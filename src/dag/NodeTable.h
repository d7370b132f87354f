// Hash-consing table for one DAG level: maps a node's canonical key to its
// index in the level's node vector (open addressing, linear probing). Keys
// live in the caller's vector, the table stores only indices.
#pragma once
#include <cstdint>
#include <vector>

#include <xxhash.h>

namespace vdbdag::dag {

inline uint64_t hashKey(uint64_t key) {  // splitmix64 finaliser
    key ^= key >> 30; key *= 0xbf58476d1ce4e5b9ull;
    key ^= key >> 27; key *= 0x94d049bb133111ebull;
    return key ^ (key >> 31);
}
template <typename Key>
inline uint64_t hashKey(const Key& key) { return XXH3_64bits(&key, sizeof(Key)); }

template <typename Key>
class NodeTable {
public:
    explicit NodeTable(std::vector<Key>& keys) : keys_(keys) { rehash(1024); }

    // Returns the index of `key` in keys_, appending it if new.
    uint32_t findOrInsert(const Key& key) {
        if ((keys_.size() + 1) * 2 > slots_.size()) rehash(slots_.size() * 2);
        const size_t mask = slots_.size() - 1;
        for (size_t i = size_t(hashKey(key)) & mask;; i = (i + 1) & mask) {
            const uint32_t slot = slots_[i];
            if (slot == 0) {
                keys_.push_back(key);
                slots_[i] = uint32_t(keys_.size());
                return uint32_t(keys_.size() - 1);
            }
            if (keys_[slot - 1] == key) return slot - 1;
        }
    }

private:
    void rehash(size_t capacity) {
        slots_.assign(capacity, 0);
        const size_t mask = capacity - 1;
        for (size_t k = 0; k < keys_.size(); ++k) {
            size_t i = size_t(hashKey(keys_[k])) & mask;
            while (slots_[i] != 0) i = (i + 1) & mask;
            slots_[i] = uint32_t(k + 1);
        }
    }
    std::vector<Key>& keys_;
    std::vector<uint32_t> slots_;
};

} // namespace vdbdag::dag
