// Writes a world's state to bytes and reads it back (WorldSnapshot::toBytes / fromBytes): one `carry`
// per class lists what it holds, and the same list both writes and reads, so the two cannot drift apart.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace soft_body_sim
{
class StateArchive;

/// A class whose member `void carry(StateArchive&)` lists its state.
template <class T, class = void>
struct HasCarry : std::false_type
{
};
template <class T>
struct HasCarry<T, std::void_t<decltype(std::declval<T&>().carry(std::declval<StateArchive&>()))>> : std::true_type
{
};

/// Values go as their bytes in this machine's order (the header's marker refuses another order);
/// containers as their size and then their elements. A reader throws std::invalid_argument when the bytes
/// end early, never reading past them, and never allocates more elements than the bytes left could hold.
class StateArchive
{
public:
  /// Writes, appending to `bytes`.
  explicit StateArchive(std::string& bytes) : out_(&bytes) {}
  /// Reads [data, data + size).
  StateArchive(const char* data, std::size_t size) : in_(data), end_(data + size) {}

  bool reading() const { return out_ == nullptr; }
  /// How many bytes a reader has not read yet.
  std::size_t left() const { return static_cast<std::size_t>(end_ - in_); }

  /// Writes or reads each value, in order.
  template <class... T>
  void operator()(T&... values)
  {
    (one(values), ...);
  }

  /// Writes or reads `size` bytes at `data`.
  void bytes(void* data, std::size_t size)
  {
    if (size == 0)
      return;
    if (!reading())
    {
      out_->append(static_cast<const char*>(data), size);
      return;
    }
    if (static_cast<std::size_t>(end_ - in_) < size)
      throw std::invalid_argument("snapshot bytes: they end early");
    std::memcpy(data, in_, size);
    in_ += size;
  }

  /// A container's size: written, or read and checked against what the bytes left can hold at
  /// `least_bytes` an element.
  std::size_t count(std::size_t size, std::size_t least_bytes)
  {
    std::uint64_t n = size;
    bytes(&n, sizeof n);
    if (reading() && n > static_cast<std::uint64_t>(end_ - in_) / least_bytes)
      throw std::invalid_argument("snapshot bytes: a size of " + std::to_string(n) + " more than they hold");
    return static_cast<std::size_t>(n);
  }

private:
  template <class T>
  struct IsVector : std::false_type
  {
  };
  template <class T, class A>
  struct IsVector<std::vector<T, A>> : std::true_type
  {
  };
  template <class T>
  struct IsOptional : std::false_type
  {
  };
  template <class T>
  struct IsOptional<std::optional<T>> : std::true_type
  {
  };
  template <class T>
  struct IsPair : std::false_type
  {
  };
  template <class A, class B>
  struct IsPair<std::pair<A, B>> : std::true_type
  {
  };
  template <class T>
  struct IsTuple : std::false_type
  {
  };
  template <class... T>
  struct IsTuple<std::tuple<T...>> : std::true_type
  {
  };
  template <class T>
  struct IsMap : std::false_type
  {
  };
  template <class K, class V, class H, class E, class A>
  struct IsMap<std::unordered_map<K, V, H, E, A>> : std::true_type
  {
  };
  template <class T>
  struct IsArray : std::false_type
  {
  };
  template <class T, std::size_t N>
  struct IsArray<std::array<T, N>> : std::true_type
  {
  };
  template <class T>
  struct IsQuaternion : std::false_type
  {
  };
  template <class S, int O>
  struct IsQuaternion<Eigen::Quaternion<S, O>> : std::true_type
  {
  };
  template <class T>
  struct IsBox : std::false_type
  {
  };
  template <class S, int D>
  struct IsBox<Eigen::AlignedBox<S, D>> : std::true_type
  {
  };

  template <class T>
  void one(T& value)
  {
    if constexpr (std::is_same_v<T, bool>)
    {
      std::uint8_t b = value ? 1 : 0;
      bytes(&b, 1);
      if (reading())
        value = b != 0;
    }
    else if constexpr (std::is_arithmetic_v<T> || std::is_enum_v<T>)
      bytes(&value, sizeof value);
    else if constexpr (std::is_array_v<T>)
    {
      for (auto& element : value)
        one(element);
    }
    else if constexpr (std::is_same_v<T, std::string>)
    {
      const std::size_t n = count(value.size(), 1);
      if (reading())
        value.resize(n);
      bytes(value.data(), n);
    }
    else if constexpr (std::is_same_v<T, std::vector<bool>>)
    {
      const std::size_t n = count(value.size(), 1);
      if (reading())
        value.resize(n);
      for (std::size_t k = 0; k < n; ++k)
      {
        bool b = value[k];
        one(b);
        if (reading())
          value[k] = b;
      }
    }
    else if constexpr (IsVector<T>::value)
    {
      using Element = typename T::value_type;
      constexpr bool flat = std::is_arithmetic_v<Element> && !std::is_same_v<Element, bool>;
      const std::size_t n = count(value.size(), flat ? sizeof(Element) : 1);
      if (reading())
        value.resize(n);
      if constexpr (flat)
        bytes(value.data(), n * sizeof(Element));
      else
        for (Element& element : value)
          one(element);
    }
    else if constexpr (IsArray<T>::value)
    {
      for (auto& element : value)
        one(element);
    }
    else if constexpr (IsPair<T>::value)
    {
      one(value.first);
      one(value.second);
    }
    else if constexpr (IsTuple<T>::value)
      std::apply([this](auto&... element) { (one(element), ...); }, value);
    else if constexpr (IsMap<T>::value)
    {
      // Its entries in its own order: a map read back finds the same values, whatever order it keeps.
      const std::size_t n = count(value.size(), 1);
      if (!reading())
        for (auto& [key, mapped] : value)
        {
          auto k = key;
          one(k);
          one(mapped);
        }
      else
      {
        value.clear();
        for (std::size_t e = 0; e < n; ++e)
        {
          std::pair<typename T::key_type, typename T::mapped_type> entry;
          one(entry.first);
          one(entry.second);
          value.insert(std::move(entry));
        }
      }
    }
    else if constexpr (IsOptional<T>::value)
    {
      bool has = value.has_value();
      one(has);
      if (reading() && has != value.has_value())
      {
        if (!has)
          value.reset();
        else if constexpr (std::is_default_constructible_v<typename T::value_type>)
          value.emplace();
        else
          throw std::invalid_argument("snapshot bytes: a part this scene does not have");
      }
      if (has)
        one(*value);
    }
    else if constexpr (IsQuaternion<T>::value)
      one(value.coeffs());
    else if constexpr (IsBox<T>::value)
    {
      one(value.min());
      one(value.max());
    }
    else if constexpr (std::is_base_of_v<Eigen::PlainObjectBase<T>, T>)
    {
      std::int64_t rows = value.rows(), cols = value.cols();
      if constexpr (T::RowsAtCompileTime == Eigen::Dynamic || T::ColsAtCompileTime == Eigen::Dynamic)
      {
        bytes(&rows, sizeof rows);
        bytes(&cols, sizeof cols);
        if (reading())
        {
          if (rows < 0 || cols < 0)
            throw std::invalid_argument("snapshot bytes: a negative matrix size");
          const auto left = static_cast<std::uint64_t>(end_ - in_) / sizeof(typename T::Scalar);
          if (rows > 0 && static_cast<std::uint64_t>(cols) > left / static_cast<std::uint64_t>(rows))
            throw std::invalid_argument("snapshot bytes: a matrix larger than they hold");
          value.resize(rows, cols);
        }
      }
      bytes(value.data(), static_cast<std::size_t>(value.size()) * sizeof(typename T::Scalar));
    }
    else if constexpr (HasCarry<T>::value)
      value.carry(*this);
    else
      carry(*this, value);  // a free function beside the type, found by its namespace
  }

  std::string* out_ = nullptr;
  const char* in_ = nullptr;
  const char* end_ = nullptr;
};

}  // namespace soft_body_sim
