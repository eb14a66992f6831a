#include "demLib/contact_history_pool.hpp"

#include <algorithm>

namespace dem {

namespace {
std::size_t grownCapacity(std::size_t used) { return used + used / 8 + 64; }
}  // namespace

void ContactHistoryPool::setRolling(bool keep) {
    if (keep == rolling_) return;
    const std::size_t slots = slotCount();
    const std::size_t oldStride = stride();
    rolling_ = keep;
    // Re-pack the records with the new stride (shear kept, rolling angle zero).
    std::vector<double> data(slots * stride(), 0.0);
    for (std::size_t s = 0; s < slots; ++s)
        for (int c = 0; c < 3; ++c) data[s * stride() + c] = data_[s * oldStride + c];
    data_.swap(data);
}

void ContactHistoryPool::reset(std::size_t entries) {
    slot_.assign(entries, -1);
    data_.clear();
}

void ContactHistoryPool::rebuild(const std::vector<int>& from, const std::vector<char>& flip,
                                 const std::vector<char>& touching) {
    // Count first, so that the new records are allocated once and exactly,
    // with room for contacts that close before the next build.
    std::size_t used = 0;
    for (std::size_t b = 0; b < from.size(); ++b)
        if ((from[b] >= 0 && slot_[from[b]] >= 0) || (!touching.empty() && touching[b])) ++used;
    const std::size_t width = stride();
    std::vector<int> slot(from.size(), -1);
    std::vector<double> data;
    data.reserve(grownCapacity(used) * width);
    data.resize(used * width, 0.0);
    int next = 0;
    for (std::size_t b = 0; b < from.size(); ++b) {
        const int old = from[b] >= 0 ? slot_[from[b]] : -1;
        if (old < 0 && (touching.empty() || !touching[b])) continue;
        slot[b] = next;
        if (old >= 0) {
            const double sign = !flip.empty() && flip[b] ? -1.0 : 1.0;
            for (std::size_t c = 0; c < width; ++c) data[next * width + c] = sign * data_[old * width + c];
        }
        ++next;
    }
    slot_.swap(slot);
    data_.swap(data);
}

void ContactHistoryPool::repack(std::vector<int>& source) {
    const std::size_t width = stride();
    const int oldSlots = static_cast<int>(slotCount());
    // New slots in list order; fresh ones remembered.
    int used = 0;
    std::vector<int> fresh;
    for (int& s : source) {
        if (s == -1) continue;
        if (s == freshRecord) fresh.push_back(used);
        ++used;
    }
    const int span = std::max(oldSlots, used);
    // Where each record goes: carried records to their new slot; the rest (old
    // records no entry continues, and room beyond the old records) fill the
    // fresh slots first and then the tail, which is cut off at the end.
    std::vector<int>& target = map_;
    target.assign(span, -1);
    {
        int next = 0;
        for (int& s : source) {
            if (s == -1) continue;
            if (s >= 0) target[s] = next;
            s = next++;
        }
    }
    {
        std::size_t f = 0;
        int tail = used;
        for (int r = 0; r < span; ++r)
            if (target[r] < 0) target[r] = f < fresh.size() ? fresh[f++] : tail++;
    }
    if (data_.capacity() < static_cast<std::size_t>(span) * width) {
        // More contacts than records (rare): grow once, with the usual room.
        std::vector<double> grown;
        grown.reserve(grownCapacity(span) * width);
        grown.assign(data_.begin(), data_.end());
        data_.swap(grown);
    }
    data_.resize(static_cast<std::size_t>(span) * width, 0.0);
    // Apply the permutation by cycles: each swap puts one record in place.
    for (int r = 0; r < span; ++r)
        while (target[r] != r) {
            const int t = target[r];
            std::swap_ranges(&data_[r * width], &data_[r * width] + width, &data_[t * width]);
            std::swap(target[r], target[t]);
        }
    for (int s : fresh) std::fill_n(&data_[s * width], width, 0.0);
    data_.resize(static_cast<std::size_t>(used) * width);  // capacity kept: room for new contacts
    slot_.swap(source);
}

int ContactHistoryPool::takeSlot() {
    // Grow by an eighth, not the doubling of vector: the records are a large
    // part of the memory, and a copy holds the old and new block at once.
    if (data_.size() == data_.capacity()) data_.reserve(grownCapacity(slotCount()) * stride());
    data_.resize(data_.size() + stride(), 0.0);
    return static_cast<int>(slotCount()) - 1;
}

void ContactHistoryPool::set(std::size_t k, const ContactHistory& h) {
    if (wake(slot_[k]) < 0) slot_[k] = takeSlot();
    double* r = record(slot_[k]);
    Vec3::Map(r) = h.shear;
    if (rolling_) Vec3::Map(r + 3) = h.rollingAngle;
}

void ContactHistoryPool::commit(const std::vector<Changes>& changes) {
    for (const Changes& c : changes)
        for (const Changes::Opened& o : c.opened) set(o.entry, o.history);
}

std::size_t ContactHistoryPool::bytes() const {
    return slot_.capacity() * sizeof(int) + data_.capacity() * sizeof(double) + map_.capacity() * sizeof(int);
}

std::size_t ContactHistoryPool::contactsWithHistory() const {
    return static_cast<std::size_t>(std::count_if(slot_.begin(), slot_.end(), [](int s) { return s >= 0; }));
}

}  // namespace dem
