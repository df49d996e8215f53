#pragma once
/// \file
/// touchdown's one extension mechanism: a registry of named factories, each
/// with a one-line description. The built-in landing systems are registered
/// in one (scenario/system_registry.hpp), and so is anything a plug-in
/// library adds; the command line names an entry, the library takes the
/// factory. Thread-safe: entries may be added (a plug-in loaded) while
/// other threads look them up.
#include <algorithm>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "touchdown/core/error.hpp"

namespace touchdown {

template <class Factory>
class Registry {
 public:
  struct Entry {
    std::string name;
    std::string description;  ///< one line, for listings and --help
    Factory factory;
    /// One line: the options the factory reads (empty: none), for listings.
    std::string options;
  };

  /// `what` names the kind of thing in messages ("landing system").
  explicit Registry(std::string what) : what_(std::move(what)) {}

  /// Adds an entry with no options.
  void add(std::string name, std::string description, Factory factory) {
    add(std::move(name), std::move(description), std::string(), std::move(factory));
  }

  /// Adds an entry. Throws InvalidArgument for an empty name, a name with
  /// a character outside [A-Za-z0-9._-] (names go on command lines and
  /// into spec strings such as plugin:PATH:NAME), a description or options
  /// with a line break, or a name that is already registered.
  void add(std::string name, std::string description, std::string options, Factory factory) {
    if (name.empty()) throw InvalidArgument(what_ + ": empty name");
    const auto bad = std::find_if_not(name.begin(), name.end(), [](char c) {
      return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
             c == '-';
    });
    if (bad != name.end()) {
      throw InvalidArgument(what_ + " '" + name + "': names use only letters, digits, '.', '_' and '-'");
    }
    if (description.find_first_of("\r\n") != std::string::npos) {
      throw InvalidArgument(what_ + " '" + name + "': the description must be one line");
    }
    if (options.find_first_of("\r\n") != std::string::npos) {
      throw InvalidArgument(what_ + " '" + name + "': the options must be one line");
    }
    const std::lock_guard lock(mutex_);
    if (find_locked(name) != nullptr) throw InvalidArgument(what_ + " '" + name + "' is already registered");
    entries_.push_back(Entry{std::move(name), std::move(description), std::move(factory), std::move(options)});
  }

  /// Removes the entry named `name`; false when there was none. For a
  /// caller that registered something for a limited time (a test, a host
  /// that unloads what it added); a factory already taken stays valid.
  bool remove(std::string_view name) {
    const std::lock_guard lock(mutex_);
    const auto it = std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.name == name; });
    if (it == entries_.end()) return false;
    entries_.erase(it);
    return true;
  }

  /// The entry named `name`, or nullopt.
  [[nodiscard]] std::optional<Entry> find(std::string_view name) const {
    const std::lock_guard lock(mutex_);
    const Entry* e = find_locked(name);
    return e != nullptr ? std::optional<Entry>(*e) : std::nullopt;
  }

  /// The entry named `name`; throws InvalidArgument naming the known ones.
  [[nodiscard]] Entry get(std::string_view name) const {
    if (auto e = find(name)) return *e;
    throw InvalidArgument(what_ + ": " + unknown(name));
  }

  /// Every entry, sorted by name.
  [[nodiscard]] std::vector<Entry> entries() const {
    std::vector<Entry> out;
    {
      const std::lock_guard lock(mutex_);
      out = entries_;
    }
    std::sort(out.begin(), out.end(), [](const Entry& a, const Entry& b) { return a.name < b.name; });
    return out;
  }

  [[nodiscard]] std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const Entry& e : entries()) out.push_back(e.name);
    return out;
  }

  /// "unknown 'NAME' (known: a, b)": the message for a name not registered
  /// (get() prefixes it with what the registry holds, an option's
  /// validate() with its key).
  [[nodiscard]] std::string unknown(std::string_view name) const {
    return "unknown '" + std::string(name) + "' (known: " + known() + ")";
  }

  /// The names, sorted, comma-separated: for messages and --help.
  [[nodiscard]] std::string known() const {
    std::string out;
    for (const std::string& n : names()) out += (out.empty() ? "" : ", ") + n;
    return out;
  }

 private:
  const Entry* find_locked(std::string_view name) const {
    const auto it = std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.name == name; });
    return it != entries_.end() ? &*it : nullptr;
  }

  std::string what_;
  mutable std::mutex mutex_;
  std::vector<Entry> entries_;
};

}  // namespace touchdown
