#pragma once
// Contact history (tangential spring, rolling spring) of the listed particle
// pairs, stored only for pairs in contact.  A Verlet list with a skin holds
// about twice as many pairs as touch (3.8 vs 1.9 per particle in a settled
// bed), and a pair out of contact has zero history: so each listed pair has a
// slot index (-1: no history, i.e. zero) into compact pools, instead of 24-48
// bytes of zeros.  The pools are compacted in list order at every list build
// or reorder, so the force loop reads them nearly in sequence.
//
// A contact that opens keeps its record until the next list build, marked
// resting (slot -3 - s, history zero), and takes it back if the same pair
// touches again.  Contacts flicker in a dense bed; handing their records back
// to a shared free list scattered the records of each force-loop thread over
// the other's (the two cores then fought over the cache lines) and out of list
// order.  New slots are handed out between force loops (commit), in thread
// order: the layout depends only on the thread count, and the physics not on
// the layout at all.
#include <cstddef>
#include <vector>

#include "demLib/contact_law.hpp"
#include "demLib/vec3.hpp"

namespace dem {

class ContactHistoryPool {
public:
    // Whether the rolling spring (rolled angle) is kept (EPSD models); otherwise it reads as zero.
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
    // Resting slots (see above): the slot value of resting record s, and back.
    static constexpr bool isResting(int slot) { return slot <= -3; }
    static constexpr int resting(int record) { return -3 - record; }
    static constexpr int restingRecord(int slot) { return -3 - slot; }
    // One entry's slot, in the pool or in the force kernel's raw slot array:
    // the contact opened (its record rests), or touches again (a resting
    // record is taken back; returns the record, or -1 for none).
    static void rest(int& slot) {
        if (slot >= 0) slot = resting(slot);
    }
    static int wake(int& slot) {
        if (isResting(slot)) slot = restingRecord(slot);
        return slot;
    }
    // Hands out the slot array (the pool then has no entries), e.g. to reuse
    // its memory once the slots were copied elsewhere.
    std::vector<int> releaseSlots() { return std::move(slot_); }

    std::size_t entries() const { return slot_.size(); }
    ContactHistory get(std::size_t k) const {
        ContactHistory h;
        const int s = slot_[k];
        if (s >= 0) {
            h.shear = Vec3::Map(&data_[s * stride()]);
            if (rolling_) h.rollingAngle = Vec3::Map(&data_[s * stride() + 3]);
        }
        return h;
    }
    // Stores the history of entry k (a resting record is taken back, else a
    // slot is taken if it has none).
    void set(std::size_t k, const ContactHistory& h);
    // Entry k's contact opened: its history is zero from now on (its record rests).
    void open(std::size_t k) { rest(slot_[k]); }

    // Hot-loop access for the force kernel: the slot of each entry, and the
    // records: slot s holds the shear at record(s) and, if keepsRolling(), the
    // rolled angle right after it (one cache line per contact, not two).
    int* slots() { return slot_.data(); }
    int slot(std::size_t k) const { return slot_[k]; }
    double* record(int s) { return data_.data() + static_cast<std::size_t>(s) * stride(); }
    std::size_t stride() const { return rolling_ ? 6 : 3; }

    // What one thread of a force loop changed: the histories of new contacts
    // (entries without a slot, resting or not).
    struct Changes {
        struct Opened {
            int entry;
            ContactHistory history;
        };
        std::vector<Opened> opened;
        void clear() { opened.clear(); }
    };
    // Applies the changes of all threads, in thread order.
    void commit(const std::vector<Changes>& changes);

    // Entries with a (non-zero) history, and records held (those and the resting ones).
    std::size_t contactsWithHistory() const;
    std::size_t records() const { return slotCount(); }
    std::size_t bytes() const;

private:
    int takeSlot();
    std::size_t slotCount() const { return data_.size() / stride(); }

    bool rolling_ = true;
    std::vector<int> slot_;  // per list entry: record, -1 none, or resting (see above)
    std::vector<double> data_;  // stride() doubles per slot
    std::vector<int> map_;  // repack's work array, kept for its memory
};

}  // namespace dem
