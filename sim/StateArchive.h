#pragma once
// A simulation's evolving state as bytes: what a checkpoint holds so that a run restarted from it
// continues with the same bits as one that never stopped. Each stateful class lists its fields
// once, in a `template <class Self, class Archive> static void visitState(Self& s, Archive& a)`
// that calls a(s.field) for each (Self is const when writing); StateWriter appends them and
// StateReader reads them back in the same order. What a
// class derives from its parameters at set-up is not listed: the reader's object is built from
// the same scene first.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace rend::sim {

/// A checkpoint that does not fit the object it is read into (truncated, or another scene's).
struct StateMismatch : std::runtime_error {
    using std::runtime_error::runtime_error;
};

namespace detail {

template <class T>
struct IsFixedEigen : std::false_type {};
template <class S, int R, int C, int O, int MR, int MC>
struct IsFixedEigen<Eigen::Matrix<S, R, C, O, MR, MC>>
    : std::bool_constant<(R > 0 && C > 0 && std::is_arithmetic_v<S>)> {};

/// Stored as its bytes: trivially copyable types and fixed-size Eigen matrices (whose copy
/// constructor is user-provided but whose storage is its coefficients).
template <class T>
inline constexpr bool kRaw = std::is_trivially_copyable_v<T> || IsFixedEigen<T>::value;

}  // namespace detail

class StateWriter {
public:
    /// Writes into `reuse`'s storage (emptied first): a caller that saves every frame keeps its
    /// pages, rather than growing a new buffer through every size up to the state's.
    explicit StateWriter(std::vector<std::byte> reuse = {}) : bytes_(std::move(reuse)) {
        bytes_.clear();
    }
    template <class T>
    requires detail::kRaw<T>
    void operator()(const T& value) { append(&value, sizeof(T)); }
    template <class T>
    requires detail::kRaw<T>
    void operator()(const std::vector<T>& values) {
        const std::uint64_t count = values.size();
        append(&count, sizeof count);
        append(values.data(), values.size() * sizeof(T));
    }
    /// A vector of `count` values, the k-th `value(k)`, read back as one (StateReader's
    /// operator()(std::vector<T>&)): a selection of another array, saved without a copy of it.
    template <class T, class Value>
    requires detail::kRaw<T>
    void vectorOf(std::uint64_t count, Value value) {
        append(&count, sizeof count);
        const std::size_t at = bytes_.size();
        bytes_.resize(at + count * sizeof(T));
        for (std::uint64_t k = 0; k < count; ++k) {
            const T v = value(k);
            std::memcpy(bytes_.data() + at + k * sizeof(T), &v, sizeof(T));
        }
    }
    const std::vector<std::byte>& bytes() const { return bytes_; }
    std::vector<std::byte> take() { return std::move(bytes_); }

private:
    void append(const void* data, std::size_t size) {
        const auto* p = static_cast<const std::byte*>(data);
        bytes_.insert(bytes_.end(), p, p + size);
    }
    std::vector<std::byte> bytes_;
};

class StateReader {
public:
    explicit StateReader(std::span<const std::byte> bytes) : bytes_(bytes) {}

    template <class T>
    requires detail::kRaw<T>
    void operator()(T& value) { take(&value, sizeof(T)); }
    /// Reads a vector into `values`, resized to the stored count.
    template <class T>
    requires detail::kRaw<T>
    void operator()(std::vector<T>& values) {
        std::uint64_t count = 0;
        take(&count, sizeof count);
        if (count > (bytes_.size() - at_) / std::max<std::size_t>(sizeof(T), 1))
            throw StateMismatch("the state ends inside an array of " + std::to_string(count) +
                                " values");
        values.resize(count);
        take(values.data(), count * sizeof(T));
    }
    /// Throws unless every byte was read.
    void finish() const {
        if (at_ != bytes_.size())
            throw StateMismatch(std::to_string(bytes_.size() - at_) +
                                " bytes of state left over: written by another scene or version");
    }

private:
    void take(void* data, std::size_t size) {
        if (size > bytes_.size() - at_)
            throw StateMismatch("the state ends " + std::to_string(size - (bytes_.size() - at_)) +
                                " bytes early");
        if (size) std::memcpy(data, bytes_.data() + at_, size);
        at_ += size;
    }
    std::span<const std::byte> bytes_;
    std::size_t at_ = 0;
};

/// Checks, on reading, that a size derived from the scene matches the one written.
template <class Archive>
void expectSize(Archive& a, std::uint64_t size, const char* what) {
    std::uint64_t stored = size;
    a(stored);
    if (stored != size)
        throw StateMismatch(std::string("the state holds ") + std::to_string(stored) + " " + what +
                            ", this scene " + std::to_string(size));
}

}  // namespace rend::sim
