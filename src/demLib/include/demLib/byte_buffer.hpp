#pragma once
// Byte buffers of plain values for the messages between ranks (the same
// executable on every rank: no byte-order or layout conversion).  Used by the
// ghost exchange, the gathered restart files and the gathered particle output.
#include <cstdint>
#include <cstring>
#include <vector>

#include "demLib/error.hpp"
#include "demLib/vec3.hpp"

namespace dem {

struct ByteWriter {
    std::vector<char>& out;
    template <class T>
    void put(const T& v) {
        const std::size_t at = out.size();
        out.resize(at + sizeof(T));
        std::memcpy(out.data() + at, static_cast<const void*>(&v), sizeof(T));
    }
    void put(const Vec3& v) {
        put(v.x());
        put(v.y());
        put(v.z());
    }
    // A whole vector, its length first.
    template <class T>
    void putVector(const std::vector<T>& v) {
        put(static_cast<std::uint64_t>(v.size()));
        const std::size_t at = out.size();
        out.resize(at + v.size() * sizeof(T));
        if (!v.empty()) std::memcpy(out.data() + at, static_cast<const void*>(v.data()), v.size() * sizeof(T));
    }
};

struct ByteReader {
    const std::vector<char>& in;
    std::size_t at = 0;
    template <class T>
    T get() {
        need(sizeof(T));
        T v;
        std::memcpy(static_cast<void*>(&v), in.data() + at, sizeof(T));
        at += sizeof(T);
        return v;
    }
    Vec3 vec() {
        const double x = get<double>(), y = get<double>(), z = get<double>();
        return Vec3(x, y, z);
    }
    // A vector written by putVector, appended to `v`.
    template <class T>
    void appendVector(std::vector<T>& v) {
        const auto n = static_cast<std::size_t>(get<std::uint64_t>());
        need(n * sizeof(T));
        const std::size_t old = v.size();
        v.resize(old + n);
        if (n) std::memcpy(static_cast<void*>(v.data() + old), in.data() + at, n * sizeof(T));
        at += n * sizeof(T);
    }
    bool done() const { return at == in.size(); }

private:
    void need(std::size_t bytes) const {
        if (at + bytes > in.size()) throw RuntimeError("demLib: truncated message between ranks");
    }
};

}  // namespace dem
