#pragma once
// Contact history (tangential spring, rolling spring) of the listed particle
// pairs, stored only for pairs in contact.  A Verlet list with a skin holds
// about twice as many pairs as touch (3.8 vs 1.9 per particle in a settled
// bed), and a pair out of contact has zero history: so each listed pair has a
// slot index (-1: no history, i.e. zero) into compact pools, instead of 24-48
// bytes of zeros.  The pools are compacted in list order at every list build
// or reorder, so the force loop reads them nearly in sequence.
//
// Slots are handed out and returned between force loops (commit), in thread
// order: the layout depends only on the thread count, and the physics not on
// the layout at all.
#include <cstddef>
#include <vector>

#include "demLib/contact_law.hpp"
#include "demLib/vec3.hpp"

namespace dem {

class ContactHistoryPool {
public:
    // Whether the rolling spring torque is kept (EPSD models); otherwise it reads as zero.
    void setRolling(bool keep);
    bool keepsRolling() const { return rolling_; }

    // Entry count of the pair list, all without history.
    void reset(std::size_t entries);

    // The list was rebuilt or reordered: new entry b continues old entry
    // from[b] (-1: new pair); flip[b] (may be empty: none) negates its vectors
    // (the pair is now seen from its other particle); touching[b] (may be
    // empty) reserves a zero slot for a pair already in contact.
    void rebuild(const std::vector<int>& from, const std::vector<char>& flip, const std::vector<char>& touching);

    // The list was rebuilt (pairs keep their orientation): source[b] is the
    // slot whose record new entry b continues, freshRecord for a pair already
    // in contact that gets a zero record, -1 for none.  The records are
    // permuted into list order in place (no second copy of them); on return
    // `source` holds the old slot array, as a buffer for the next build.
    static constexpr int freshRecord = -2;
    void repack(std::vector<int>& source);
    // Hands out the slot array (the pool then has no entries), e.g. to reuse
    // its memory once the slots were copied elsewhere.
    std::vector<int> releaseSlots() { return std::move(slot_); }

    std::size_t entries() const { return slot_.size(); }
    ContactHistory get(std::size_t k) const {
        ContactHistory h;
        const int s = slot_[k];
        if (s >= 0) {
            h.shear = Vec3::Map(&data_[s * stride()]);
            if (rolling_) h.rollingTorque = Vec3::Map(&data_[s * stride() + 3]);
        }
        return h;
    }
    // Stores the history of entry k (a slot is taken if it has none).
    void set(std::size_t k, const ContactHistory& h);

    // Hot-loop access for the force kernel: the slot of each entry, and the
    // records: slot s holds the shear at record(s) and, if keepsRolling(), the
    // rolling torque right after it (one cache line per contact, not two).
    int* slots() { return slot_.data(); }
    double* record(int s) { return data_.data() + static_cast<std::size_t>(s) * stride(); }
    std::size_t stride() const { return rolling_ ? 6 : 3; }

    // What one thread of a force loop changed: slots of contacts that opened
    // (already set to -1 in slots()) and histories of new contacts.
    struct Changes {
        struct Opened {
            int entry;
            ContactHistory history;
        };
        std::vector<int> released;
        std::vector<Opened> opened;
        void clear() {
            released.clear();
            opened.clear();
        }
    };
    // Applies the changes of all threads, in thread order.
    void commit(const std::vector<Changes>& changes);

    std::size_t slotsInUse() const { return slotCount() - free_.size(); }
    std::size_t bytes() const;

private:
    int takeSlot();
    std::size_t slotCount() const { return data_.size() / stride(); }

    bool rolling_ = true;
    std::vector<int> slot_;  // per list entry
    std::vector<double> data_;  // stride() doubles per slot
    std::vector<int> free_;  // returned slots, reused last-in first-out
};

}  // namespace dem
