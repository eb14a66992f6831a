#pragma once
// A small RAII layer over the HDF5 C API: just what demLib's field output and
// restart files need (2D double/int datasets, scalar attributes, groups).
#include <cstdint>
#include <string>
#include <vector>

#include "demLib/error.hpp"
#include "demLib/vec3.hpp"

namespace dem {

class Hdf5File {
public:
    // Create (or truncate), Read only, or Update (an existing file, read and write).
    enum class Mode { Create, Read, Update };
    Hdf5File(const std::string& path, Mode mode);
    ~Hdf5File();
    Hdf5File(const Hdf5File&) = delete;
    Hdf5File& operator=(const Hdf5File&) = delete;

    const std::string& path() const { return path_; }

    void createGroup(const std::string& name);
    bool exists(const std::string& name) const;
    // Renames (moves) a dataset or group; the target's group must exist.
    void rename(const std::string& from, const std::string& to);

    void write(const std::string& name, const std::vector<double>& data, std::size_t columns = 1);
    void write(const std::string& name, const std::vector<std::int64_t>& data, std::size_t columns = 1);
    void write(const std::string& name, const std::vector<int>& data, std::size_t columns = 1);
    void write(const std::string& name, const std::vector<Vec3>& data);

    std::vector<double> readDoubles(const std::string& name, std::size_t* columns = nullptr) const;
    std::vector<std::int64_t> readInt64(const std::string& name) const;
    std::vector<int> readInts(const std::string& name) const;
    std::vector<Vec3> readVec3(const std::string& name) const;

    // Scalar attributes on the root group.
    void setAttribute(const std::string& name, double value);
    void setAttribute(const std::string& name, std::int64_t value);
    void setAttribute(const std::string& name, const std::string& value);
    double doubleAttribute(const std::string& name) const;
    std::int64_t intAttribute(const std::string& name) const;
    std::string stringAttribute(const std::string& name) const;
    bool hasAttribute(const std::string& name) const;

    // Datasets read so far that carry no checksum (files written before checksums
    // existed); a dataset whose data do not match its checksum throws DamagedFileError.
    std::size_t uncheckedDatasets() const { return unchecked_; }
    // Writes the checksum of the root group's attributes (call after the last setAttribute).
    void sealAttributes();
    // False when the file has no such checksum; throws DamagedFileError when it does not match.
    bool checkAttributes() const;

private:
    std::string path_;
    std::int64_t file_ = -1;  // hid_t
    mutable std::size_t unchecked_ = 0;
};

}  // namespace dem
