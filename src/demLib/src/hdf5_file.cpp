#include "demLib/hdf5_file.hpp"

#include <hdf5.h>

#include "demLib/checksum.hpp"
#include "demLib/error.hpp"

namespace dem {

namespace {

struct Handle {
    hid_t id;
    herr_t (*close)(hid_t);
    ~Handle() {
        if (id >= 0) close(id);
    }
};

[[noreturn]] void fail(const std::string& path, const std::string& what) {
    throw RuntimeError("HDF5 file '" + path + "': " + what);
}

constexpr const char* checksumAttribute = "checksum";

// Every dataset carries the checksum of its data (demLib/checksum.hpp), checked when it is read.
template <class T>
void writeDataset(hid_t file, const std::string& path, const std::string& name, hid_t type, const T* data,
                  std::size_t rows, std::size_t columns) {
    const hsize_t dims[2] = {rows, columns};
    Handle space{H5Screate_simple(columns == 1 ? 1 : 2, dims, nullptr), H5Sclose};
    Handle set{H5Dcreate2(file, name.c_str(), type, space.id, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose};
    if (set.id < 0) fail(path, "cannot create dataset '" + name + "'");
    if (rows > 0 && H5Dwrite(set.id, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
        fail(path, "cannot write dataset '" + name + "'");
    const std::uint64_t sum = rows > 0 ? datasetChecksum(data, rows, columns * sizeof(T)) : 0;
    Handle scalar{H5Screate(H5S_SCALAR), H5Sclose};
    Handle attr{H5Acreate2(set.id, checksumAttribute, H5T_NATIVE_UINT64, scalar.id, H5P_DEFAULT, H5P_DEFAULT),
                H5Aclose};
    if (attr.id < 0 || H5Awrite(attr.id, H5T_NATIVE_UINT64, &sum) < 0)
        fail(path, "cannot write the checksum of dataset '" + name + "'");
}

template <class T>
std::vector<T> readDataset(hid_t file, const std::string& path, const std::string& name, hid_t type,
                           std::size_t* columns, std::size_t& unchecked) {
    Handle set{H5Dopen2(file, name.c_str(), H5P_DEFAULT), H5Dclose};
    if (set.id < 0) fail(path, "missing dataset '" + name + "'");
    Handle space{H5Dget_space(set.id), H5Sclose};
    hsize_t dims[2] = {0, 1};
    const int rank = H5Sget_simple_extent_dims(space.id, dims, nullptr);
    if (rank < 1 || rank > 2) fail(path, "dataset '" + name + "' has an unexpected rank");
    if (rank == 1) dims[1] = 1;
    std::vector<T> out(dims[0] * dims[1]);
    if (!out.empty() && H5Dread(set.id, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) < 0)
        fail(path, "cannot read dataset '" + name + "'");
    if (columns) *columns = dims[1];
    if (H5Aexists(set.id, checksumAttribute) > 0) {
        std::uint64_t stored = 0;
        Handle attr{H5Aopen(set.id, checksumAttribute, H5P_DEFAULT), H5Aclose};
        if (attr.id < 0 || H5Aread(attr.id, H5T_NATIVE_UINT64, &stored) < 0)
            throw DamagedFileError("HDF5 file '" + path + "' is damaged: the checksum of dataset '" + name +
                                   "' cannot be read");
        const std::uint64_t computed = out.empty() ? 0 : datasetChecksum(out.data(), dims[0], dims[1] * sizeof(T));
        if (computed != stored)
            throw DamagedFileError("HDF5 file '" + path + "' is damaged: the data of dataset '" + name +
                                   "' do not match their checksum (changed since they were written)");
    } else {
        ++unchecked;  // written before datasets carried checksums
    }
    return out;
}

}  // namespace

Hdf5File::Hdf5File(const std::string& path, Mode mode) : path_(path) {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // we report errors ourselves
    if (mode == Mode::Create)
        file_ = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    else
        file_ = H5Fopen(path.c_str(), mode == Mode::Update ? H5F_ACC_RDWR : H5F_ACC_RDONLY, H5P_DEFAULT);
    // Creating is the filesystem's business (a folder not writable, a name taken by a
    // folder); opening a file that is there but not HDF5 is the input's.
    if (file_ < 0 && mode == Mode::Create) throw RuntimeError("HDF5 file '" + path + "': cannot create it");
    if (file_ < 0) throw InputError("HDF5 file '" + path + "': cannot open it (missing or not HDF5)");
}

Hdf5File::~Hdf5File() {
    if (file_ >= 0) H5Fclose(file_);
}

void Hdf5File::createGroup(const std::string& name) {
    Handle g{H5Gcreate2(file_, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose};
    if (g.id < 0) fail(path_, "cannot create group '" + name + "'");
}

bool Hdf5File::exists(const std::string& name) const { return H5Lexists(file_, name.c_str(), H5P_DEFAULT) > 0; }

void Hdf5File::rename(const std::string& from, const std::string& to) {
    if (H5Lmove(file_, from.c_str(), file_, to.c_str(), H5P_DEFAULT, H5P_DEFAULT) < 0)
        fail(path_, "cannot rename '" + from + "' to '" + to + "'");
}

void Hdf5File::write(const std::string& name, const std::vector<double>& data, std::size_t columns) {
    writeDataset(file_, path_, name, H5T_NATIVE_DOUBLE, data.data(), data.size() / columns, columns);
}
void Hdf5File::write(const std::string& name, const std::vector<std::int64_t>& data, std::size_t columns) {
    writeDataset(file_, path_, name, H5T_NATIVE_INT64, data.data(), data.size() / columns, columns);
}
void Hdf5File::write(const std::string& name, const std::vector<int>& data, std::size_t columns) {
    writeDataset(file_, path_, name, H5T_NATIVE_INT, data.data(), data.size() / columns, columns);
}
void Hdf5File::write(const std::string& name, const std::vector<Vec3>& data) {
    static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 must be three packed doubles");
    writeDataset(file_, path_, name, H5T_NATIVE_DOUBLE, data.empty() ? nullptr : data[0].data(), data.size(), 3);
}

std::vector<double> Hdf5File::readDoubles(const std::string& name, std::size_t* columns) const {
    return readDataset<double>(file_, path_, name, H5T_NATIVE_DOUBLE, columns, unchecked_);
}
std::vector<std::int64_t> Hdf5File::readInt64(const std::string& name) const {
    return readDataset<std::int64_t>(file_, path_, name, H5T_NATIVE_INT64, nullptr, unchecked_);
}
std::vector<int> Hdf5File::readInts(const std::string& name) const {
    return readDataset<int>(file_, path_, name, H5T_NATIVE_INT, nullptr, unchecked_);
}
std::vector<Vec3> Hdf5File::readVec3(const std::string& name) const {
    std::size_t columns = 0;
    const std::vector<double> flat = readDoubles(name, &columns);
    if (!flat.empty() && columns != 3) fail(path_, "dataset '" + name + "' is not a list of 3-vectors");
    std::vector<Vec3> out(flat.size() / 3);
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = Vec3(flat[3 * i], flat[3 * i + 1], flat[3 * i + 2]);
    return out;
}

namespace {
void writeAttribute(hid_t file, const std::string& path, const std::string& name, hid_t type, const void* value) {
    if (H5Aexists(file, name.c_str()) > 0) H5Adelete(file, name.c_str());
    Handle space{H5Screate(H5S_SCALAR), H5Sclose};
    Handle attr{H5Acreate2(file, name.c_str(), type, space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose};
    if (attr.id < 0 || H5Awrite(attr.id, type, value) < 0) fail(path, "cannot write attribute '" + name + "'");
}
void readAttribute(hid_t file, const std::string& path, const std::string& name, hid_t type, void* value) {
    Handle attr{H5Aopen(file, name.c_str(), H5P_DEFAULT), H5Aclose};
    if (attr.id < 0 || H5Aread(attr.id, type, value) < 0) fail(path, "missing attribute '" + name + "'");
}
}  // namespace

void Hdf5File::setAttribute(const std::string& name, double value) {
    writeAttribute(file_, path_, name, H5T_NATIVE_DOUBLE, &value);
}
void Hdf5File::setAttribute(const std::string& name, std::int64_t value) {
    writeAttribute(file_, path_, name, H5T_NATIVE_INT64, &value);
}
void Hdf5File::setAttribute(const std::string& name, const std::string& value) {
    Handle type{H5Tcopy(H5T_C_S1), H5Tclose};
    H5Tset_size(type.id, value.size() + 1);
    writeAttribute(file_, path_, name, type.id, value.c_str());
}
double Hdf5File::doubleAttribute(const std::string& name) const {
    double v = 0.0;
    readAttribute(file_, path_, name, H5T_NATIVE_DOUBLE, &v);
    return v;
}
std::int64_t Hdf5File::intAttribute(const std::string& name) const {
    std::int64_t v = 0;
    readAttribute(file_, path_, name, H5T_NATIVE_INT64, &v);
    return v;
}
bool Hdf5File::hasAttribute(const std::string& name) const { return H5Aexists(file_, name.c_str()) > 0; }

namespace {
constexpr const char* attributeChecksumName = "attributeChecksum";

// Sum over the root group's attributes (but the checksum itself) of the checksum of
// name, a zero byte and the stored value's bytes: independent of their order.
herr_t addAttributeChecksum(hid_t location, const char* name, const H5A_info_t*, void* sum) {
    if (std::string(name) == attributeChecksumName) return 0;
    Handle attr{H5Aopen(location, name, H5P_DEFAULT), H5Aclose};
    Handle type{H5Aget_type(attr.id), H5Tclose};
    Handle space{H5Aget_space(attr.id), H5Sclose};
    if (attr.id < 0 || type.id < 0 || space.id < 0) return -1;
    const std::size_t valueBytes = H5Tget_size(type.id) * static_cast<std::size_t>(H5Sget_simple_extent_npoints(space.id));
    std::vector<unsigned char> bytes(name, name + std::char_traits<char>::length(name) + 1);
    bytes.resize(bytes.size() + valueBytes);
    if (H5Aread(attr.id, type.id, bytes.data() + bytes.size() - valueBytes) < 0) return -1;
    *static_cast<std::uint64_t*>(sum) += datasetChecksum(bytes.data(), 1, bytes.size());
    return 0;
}

std::uint64_t attributesChecksum(hid_t file, const std::string& path) {
    std::uint64_t sum = 0;
    hsize_t index = 0;
    if (H5Aiterate2(file, H5_INDEX_NAME, H5_ITER_INC, &index, addAttributeChecksum, &sum) < 0)
        throw DamagedFileError("HDF5 file '" + path + "' is damaged: its attributes cannot be read");
    return sum;
}
}  // namespace

void Hdf5File::sealAttributes() {
    const std::uint64_t sum = attributesChecksum(file_, path_);
    writeAttribute(file_, path_, attributeChecksumName, H5T_NATIVE_UINT64, &sum);
}

bool Hdf5File::checkAttributes() const {
    if (!hasAttribute(attributeChecksumName)) return false;
    std::uint64_t stored = 0;
    readAttribute(file_, path_, attributeChecksumName, H5T_NATIVE_UINT64, &stored);
    if (attributesChecksum(file_, path_) != stored)
        throw DamagedFileError("HDF5 file '" + path_ + "' is damaged: its attributes (time, step, ...) do not match "
                               "their checksum (changed since they were written)");
    return true;
}
std::string Hdf5File::stringAttribute(const std::string& name) const {
    Handle attr{H5Aopen(file_, name.c_str(), H5P_DEFAULT), H5Aclose};
    if (attr.id < 0) fail(path_, "missing attribute '" + name + "'");
    Handle type{H5Aget_type(attr.id), H5Tclose};
    const std::size_t size = H5Tget_size(type.id);
    std::string v(size, '\0');
    if (H5Aread(attr.id, type.id, v.data()) < 0) fail(path_, "cannot read attribute '" + name + "'");
    v.resize(v.find('\0') == std::string::npos ? v.size() : v.find('\0'));
    return v;
}

}  // namespace dem
