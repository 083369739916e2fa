#pragma once
// std::expected for clang 14 with libstdc++ 12 (Debian bookworm), force-included into the fuzz
// build: libstdc++'s <expected> needs concepts at __cpp_concepts 202002, which clang 14 does not
// announce, so the header declares nothing there. Only what the readers use: a value or an error,
// move-only values, expected<void, E>. Compiled out wherever the real one exists.
#include <version>

#if !defined(__cpp_lib_expected)
#include <optional>
#include <type_traits>
#include <utility>
#include <variant>

namespace std {

template <class E>
class unexpected {
 public:
  template <class G = E>
  constexpr explicit unexpected(G&& e) : e_(std::forward<G>(e)) {}
  constexpr const E& error() const& noexcept { return e_; }
  constexpr E& error() & noexcept { return e_; }
  constexpr E&& error() && noexcept { return std::move(e_); }

 private:
  E e_;
};
template <class E>
unexpected(E) -> unexpected<E>;

template <class T>
inline constexpr bool is_unexpected_v = false;
template <class E>
inline constexpr bool is_unexpected_v<unexpected<E>> = true;

template <class T, class E>
class expected {
 public:
  using value_type = T;
  using error_type = E;

  constexpr expected() : v_(in_place_index<0>) {}
  template <class U = T>
    requires(!is_same_v<remove_cvref_t<U>, expected> && !is_unexpected_v<remove_cvref_t<U>> && is_constructible_v<T, U>)
  constexpr expected(U&& u) : v_(in_place_index<0>, std::forward<U>(u)) {}
  template <class G>
  constexpr expected(const unexpected<G>& u) : v_(in_place_index<1>, u.error()) {}
  template <class G>
  constexpr expected(unexpected<G>&& u) : v_(in_place_index<1>, std::move(u).error()) {}

  constexpr bool has_value() const noexcept { return v_.index() == 0; }
  constexpr explicit operator bool() const noexcept { return has_value(); }
  constexpr T& operator*() & { return *get_if<0>(&v_); }
  constexpr const T& operator*() const& { return *get_if<0>(&v_); }
  constexpr T&& operator*() && { return std::move(*get_if<0>(&v_)); }
  constexpr T* operator->() { return get_if<0>(&v_); }
  constexpr const T* operator->() const { return get_if<0>(&v_); }
  constexpr T& value() & { return get<0>(v_); }
  constexpr const T& value() const& { return get<0>(v_); }
  constexpr E& error() & { return *get_if<1>(&v_); }
  constexpr const E& error() const& { return *get_if<1>(&v_); }
  constexpr E&& error() && { return std::move(*get_if<1>(&v_)); }

 private:
  variant<T, E> v_;
};

template <class E>
class expected<void, E> {
 public:
  using value_type = void;
  using error_type = E;

  constexpr expected() = default;
  template <class G>
  constexpr expected(const unexpected<G>& u) : e_(in_place, u.error()) {}
  template <class G>
  constexpr expected(unexpected<G>&& u) : e_(in_place, std::move(u).error()) {}

  constexpr bool has_value() const noexcept { return !e_.has_value(); }
  constexpr explicit operator bool() const noexcept { return has_value(); }
  constexpr void operator*() const noexcept {}
  constexpr E& error() & { return *e_; }
  constexpr const E& error() const& { return *e_; }
  constexpr E&& error() && { return std::move(*e_); }

 private:
  optional<E> e_;
};

}  // namespace std
#endif
