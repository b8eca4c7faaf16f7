#pragma once
/// @file
/// Device arrays and host/device mirrors over a backend's memory functions (LAMMPS AtomVec style).
/// On the cpu backend (separateDevice = false) a DualArray's device pointer *is* its host
/// pointer and toDevice()/toHost() do nothing; on cuda the host side is pinned memory.

#include <cstddef>
#include <utility>

namespace coredem::dem::backend {

/// Device-only storage (scratch, sort buffers). Contents undefined after allocate().
template <class T, class Exec>
class DeviceArray {
public:
  DeviceArray() = default;
  ~DeviceArray() { Exec::freeDevice(_d); }
  DeviceArray(const DeviceArray&) = delete;
  DeviceArray& operator=(const DeviceArray&) = delete;

  /// Ensures room for n elements (never shrinks). Contents are lost when it grows.
  void reserve(std::size_t n) {
    if (n <= _cap) {
      _n = n;
      return;
    }
    Exec::freeDevice(_d);
    _d = static_cast<T*>(Exec::allocDevice(n * sizeof(T)));
    _cap = n;
    _n = n;
  }
  T* d() { return _d; }
  const T* d() const { return _d; }
  std::size_t size() const { return _n; }
  std::size_t bytes() const { return _cap * sizeof(T); }

private:
  T* _d = nullptr;
  std::size_t _n = 0, _cap = 0;
};

/// A host mirror plus device storage with explicit transfers and dirty flags.
template <class T, class Exec>
class DualArray {
public:
  DualArray() = default;
  ~DualArray() { release(); }
  DualArray(const DualArray&) = delete;
  DualArray& operator=(const DualArray&) = delete;

  /// (Re)allocates n elements; contents undefined.
  void allocate(std::size_t n) {
    if (n != _n) {
      release();
      _h = static_cast<T*>(Exec::allocHost(n * sizeof(T)));
      _d = Exec::separateDevice ? static_cast<T*>(Exec::allocDevice(n * sizeof(T))) : _h;
      _n = n;
    }
    _hostNewer = _deviceNewer = false;
  }
  T* h() { return _h; }
  const T* h() const { return _h; }
  T* d() { return _d; }
  const T* d() const { return _d; }
  std::size_t size() const { return _n; }
  /// Bytes on the device (the copy kernels use); host mirror bytes are hostBytes().
  std::size_t bytes() const { return _n * sizeof(T); }
  std::size_t hostBytes() const { return Exec::separateDevice ? _n * sizeof(T) : 0; }

  void markHostModified() { _hostNewer = true; }
  void markDeviceModified() { _deviceNewer = true; }
  /// Exchanges the buffers (and transfer state) of two arrays of the same size in bytes, of
  /// any element types: no element is copied. (The buffers' alignment, that of allocHost and
  /// allocDevice, suits every element type.)
  template <class U>
  void swapBuffers(DualArray<U, Exec>& o) noexcept {
    static_assert(alignof(T) <= 64 && alignof(U) <= 64);
    T* h = _h;
    T* d = _d;
    _h = reinterpret_cast<T*>(o._h);
    _d = reinterpret_cast<T*>(o._d);
    o._h = reinterpret_cast<U*>(h);
    o._d = reinterpret_cast<U*>(d);
    std::swap(_hostNewer, o._hostNewer);
    std::swap(_deviceNewer, o._deviceNewer);
  }
  /// Copies host → device if the host copy was modified since the last transfer.
  void toDevice() {
    if (_hostNewer)
      Exec::copyToDevice(_d, _h, bytes());
    _hostNewer = false;
  }
  /// Copies device → host if the device copy was modified since the last transfer.
  void toHost() {
    if (_deviceNewer)
      Exec::copyToHost(_h, _d, bytes());
    _deviceNewer = false;
  }

private:
  template <class, class>
  friend class DualArray;
  void release() {
    if (Exec::separateDevice)
      Exec::freeDevice(_d);
    Exec::freeHost(_h);
    _h = _d = nullptr;
    _n = 0;
  }
  T* _h = nullptr;
  T* _d = nullptr;
  std::size_t _n = 0;
  bool _hostNewer = false, _deviceNewer = false;
};

} // namespace coredem::dem::backend
