#pragma once
// Errors that demLib reports to its callers.  InputError is for anything a user
// wrote (a case file, a keyword, a value): its message names the file, the
// keyword and what was expected, and front ends print it and exit non-zero.
#include <stdexcept>
#include <string>

namespace dem {

class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// A file whose data changed after they were written (an HDF5 dataset's or attributes'
// checksum does not match): refused as input, naming the file.
class DamagedFileError : public InputError {
public:
    using InputError::InputError;
};

// A state the engine cannot continue from (NaN, lost contact with reality).
class RuntimeError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace dem
