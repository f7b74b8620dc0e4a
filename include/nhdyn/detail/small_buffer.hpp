#pragma once
/// \file detail/small_buffer.hpp
/// Scratch storage for one call of an algorithm: on the stack when the size is known at
/// compile time or small enough; beyond, in a heap block that each thread keeps for its next
/// call, so that a call on a tree of any size allocates nothing once its thread has met that
/// size.
#include <array>
#include <cstddef>
#include <memory>
#include <new>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__SANITIZE_ADDRESS__)
#define NHDYN_SCRATCH_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define NHDYN_SCRATCH_ASAN 1
#endif
#endif
#ifdef NHDYN_SCRATCH_ASAN
#include <sanitizer/asan_interface.h>
#endif

namespace nhdyn::detail {

/// Default inline capacity: about 32 KiB of T on the stack (at least 32 entries: a kernel's
/// per-body scratch of 590 bytes holds 55 bodies inline).
template <class T>
inline constexpr std::size_t inline_capacity = 32768 / sizeof(T) > 32 ? 32768 / sizeof(T) : 32;

/// The heap blocks (raw storage for T, no object in them at rest) that small_buffers beyond
/// their inline capacity borrow: one list per thread and element type, used last in, first out
/// (a call nested in another's, which runs while the outer one holds its block, gets a block
/// of its own and gives it back first). A block grows when a call needs more than it holds
/// (that call allocates); the blocks live until the thread ends: per thread and element type,
/// as many as calls nest (16 kept at most), each the size of the largest scratch it served.
/// After the thread's list is gone (a kernel run from a destructor at the thread's or the
/// program's end), each buffer allocates and frees its own block.
template <class T>
class scratch_blocks {
 public:
  class block {
   public:
    block() = default;
    explicit block(std::size_t n)
        : data_(static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(alignof(T))))), size_(n) {}
    block(block&& o) noexcept : data_(std::exchange(o.data_, nullptr)), size_(std::exchange(o.size_, 0)) {}
    block& operator=(block&& o) noexcept {
      if (this != &o) {
        release();
        data_ = std::exchange(o.data_, nullptr);
        size_ = std::exchange(o.size_, 0);
      }
      return *this;
    }
    ~block() { release(); }
    T* data() const { return data_; }
    std::size_t size() const { return size_; }

   private:
    void release() noexcept {
      if (data_) ::operator delete(static_cast<void*>(data_), std::align_val_t(alignof(T)));
      data_ = nullptr;
      size_ = 0;
    }
    T* data_ = nullptr;
    std::size_t size_ = 0;
  };

  /// Raw storage for at least n elements (under AddressSanitizer, what lies past n is poisoned:
  /// an overrun is caught as in a block of exactly n).
  static block take(std::size_t n) {
    block b;
    if (auto* free = list(); free && !free->empty()) {
      b = std::move(free->back());
      free->pop_back();
    }
    if (b.size() < n) b = block(n);
#ifdef NHDYN_SCRATCH_ASAN
    ASAN_POISON_MEMORY_REGION(b.data() + n, (b.size() - n) * sizeof(T));
#endif
    return b;
  }
  /// Back for the next call (freed when the list is full or gone).
  static void give_back(block&& b) noexcept {
#ifdef NHDYN_SCRATCH_ASAN
    ASAN_UNPOISON_MEMORY_REGION(b.data(), b.size() * sizeof(T));
#endif
    if (auto* free = list(); free && free->size() < free->capacity()) free->push_back(std::move(b));  // never allocates
  }

 private:
  struct holder {
    std::vector<block> free;
    bool& gone;
    explicit holder(bool& g) : gone(g) {
      try {
        free.reserve(16);
      } catch (...) {  // no room for the list: every buffer then allocates its own block
      }
    }
    ~holder() { gone = true; }
  };
  /// This thread's list, or null once it is destroyed (a trivially destructible flag says so).
  static std::vector<block>* list() noexcept {
    thread_local bool gone = false;
    if (gone) return nullptr;
    thread_local holder h(gone);
    return &h.free;
  }
};

/// n elements of T, default-initialised (a trivial T is left uninitialised: the algorithms
/// write every element before they read it, and a call does not pay for zeroing). Compile-time
/// N: std::array. Run time: inline storage for up to Cap elements, beyond a block borrowed from
/// this thread's scratch_blocks<T> and given back when the buffer goes; either way only n
/// elements are constructed, and destroyed with the buffer.
template <class T, int N, std::size_t Cap = inline_capacity<T>>
class small_buffer {
 public:
  explicit small_buffer(int n) {
    if (static_cast<std::size_t>(n) > Cap) [[unlikely]]
      take(n);
    else
      data_ = std::launder(reinterpret_cast<T*>(&inline_));
    if constexpr (!std::is_trivially_default_constructible_v<T> || !std::is_trivially_destructible_v<T>) {
      int i = 0;
      try {
        for (; i < n; ++i) ::new (static_cast<void*>(data_ + i)) T;
      } catch (...) {
        std::destroy_n(data_, i);
        if (heap_.data()) give_back();
        throw;
      }
      constructed_ = n;
    }
  }
  ~small_buffer() {
    std::destroy_n(data_, constructed_);
    if (heap_.data()) [[unlikely]]
      give_back();
  }
  small_buffer(const small_buffer&) = delete;
  small_buffer& operator=(const small_buffer&) = delete;
  T& operator[](int i) { return data_[i]; }
  const T& operator[](int i) const { return data_[i]; }
  T* data() { return data_; }
  const T* data() const { return data_; }

 private:
  // The heap paths out of line, so that the inline path (a pointer, a test) is what a kernel's
  // many small buffers inline: without, GCC 12 leaves the constructor and destructor of each
  // as a call (about 40 instructions a buffer, measured by callgrind on a wheeled base's lift).
  [[gnu::noinline]] void take(int n) {
    heap_ = scratch_blocks<T>::take(static_cast<std::size_t>(n));
    data_ = heap_.data();
  }
  [[gnu::noinline]] void give_back() noexcept { scratch_blocks<T>::give_back(std::move(heap_)); }

  alignas(T) std::byte inline_[sizeof(T) * Cap];
  typename scratch_blocks<T>::block heap_;
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

/// A result or workspace of type T that a call borrows from its thread and leaves, storage and
/// all, for the thread's next call: a plain call that returns a new vector runs its algorithm's
/// `evaluate` steps into it, so that the vector it returns is its only allocation once the
/// thread has met the size. A nested call, while the thread's object is borrowed, gets one of
/// its own, as does a call made after the thread's object is destroyed (from another
/// thread-local object's destructor). The object keeps whatever the last call wrote (each
/// `evaluate` rewrites what it reads).
template <class T>
class thread_kept {
 public:
  thread_kept() {
    if (T* s = busy() ? nullptr : slot()) {  // the slot first: if T's construction throws, not busy
      obj_ = s, mine_ = true, busy() = true;
    } else {
      obj_ = &local_.emplace();
    }
  }
  ~thread_kept() {
    if (mine_) busy() = false;
  }
  thread_kept(const thread_kept&) = delete;
  thread_kept& operator=(const thread_kept&) = delete;
  T& operator*() { return *obj_; }

 private:
  struct holder {
    T obj{};
    bool& gone;
    explicit holder(bool& g) : gone(g) {}
    ~holder() { gone = true; }
  };
  /// This thread's object, or null once it is destroyed (a trivially destructible flag says so).
  static T* slot() {
    thread_local bool gone = false;
    if (gone) return nullptr;
    thread_local holder h(gone);
    return &h.obj;
  }
  static bool& busy() {
    thread_local bool b = false;
    return b;
  }
  bool mine_ = false;
  std::optional<T> local_{};
  T* obj_ = nullptr;
};

/// run(T&) on the T its thread keeps (thread_kept) when Kept — a run-time size, whose storage
/// is worth keeping — else on a T of its own (a fixed size: on the stack); returns what run
/// returns, by value. A plain call runs its `evaluate` steps this way, so that what it returns
/// is its only allocation.
template <class T, bool Kept = true, class Run>
auto with_kept(Run&& run) {
  if constexpr (Kept) {
    thread_kept<T> kept;
    return run(*kept);
  } else {
    T local;
    return run(local);
  }
}

}  // namespace nhdyn::detail
