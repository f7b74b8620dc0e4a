#pragma once
/// \file detail/small_buffer.hpp
/// Scratch storage for one call of an algorithm: on the stack when the size is known at
/// compile time or small enough, on the heap only for very long run-time-sized chains.
#include <array>
#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <vector>

namespace nhdyn::detail {

/// Default inline capacity: about 32 KiB of T on the stack (at least 32 entries: a kernel's
/// per-body scratch of 590 bytes holds 55 bodies inline).
template <class T>
inline constexpr std::size_t inline_capacity = 32768 / sizeof(T) > 32 ? 32768 / sizeof(T) : 32;

/// n elements of T, default-initialised (a trivial T is left uninitialised: the algorithms
/// write every element before they read it, and a call does not pay for zeroing). Compile-time N: std::array. Run time: inline
/// storage for up to Cap elements (only n of them are constructed), heap beyond.
template <class T, int N, std::size_t Cap = inline_capacity<T>>
class small_buffer {
 public:
  explicit small_buffer(int n) {
    if (static_cast<std::size_t>(n) > Cap) {
      heap_.reset(new T[static_cast<std::size_t>(n)]);  // default-initialised: not zeroed either
      data_ = heap_.get();
    } else {
      data_ = std::launder(reinterpret_cast<T*>(&inline_));
      if constexpr (!std::is_trivially_default_constructible_v<T> || !std::is_trivially_destructible_v<T>) {
        for (int i = 0; i < n; ++i) ::new (static_cast<void*>(data_ + i)) T;
        constructed_ = n;
      }
    }
  }
  ~small_buffer() { std::destroy_n(data_, constructed_); }
  small_buffer(const small_buffer&) = delete;
  small_buffer& operator=(const small_buffer&) = delete;
  T& operator[](int i) { return data_[i]; }
  const T& operator[](int i) const { return data_[i]; }
  T* data() { return data_; }
  const T* data() const { return data_; }

 private:
  alignas(T) std::byte inline_[sizeof(T) * Cap];
  std::unique_ptr<T[]> heap_;
  T* data_ = nullptr;
  int constructed_ = 0;
};

template <class T, int N, std::size_t Cap>
  requires(N > 0)
class small_buffer<T, N, Cap> {
 public:
  explicit small_buffer(int) {}
  T& operator[](int i) { return data_[static_cast<std::size_t>(i)]; }
  const T& operator[](int i) const { return data_[static_cast<std::size_t>(i)]; }
  T* data() { return data_.data(); }
  const T* data() const { return data_.data(); }

 private:
  std::array<T, static_cast<std::size_t>(N)> data_;
};

}  // namespace nhdyn::detail
