// SPDX-License-Identifier: MIT
// JsonNode: one value of a scene file together with its path, and the checks every field of
// the schema goes through. A failed check throws SceneError naming the path and what was
// expected ("colliders[2].shape.radius: expected a positive number, got -1").
#ifndef SPH_TOOLS_JSON_NODE_H
#define SPH_TOOLS_JSON_NODE_H

#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sph_c.h"

namespace sph_tools {

class JsonNode {
 public:
  JsonNode(const nlohmann::json* value, std::string path) : value_(value), path_(std::move(path)) {}

  bool missing() const { return value_ == nullptr; }
  const std::string& path() const { return path_; }
  const nlohmann::json& json() const { return *value_; }

  // Throws SceneError(path, expected + ", got ..."), or "missing (expected ...)" when absent.
  [[noreturn]] void fail(const std::string& expected) const;

  // An object whose keys are all in `allowed` ("comment" is always allowed). `what` names the
  // object in the error ("a collider").
  void expect_object(const char* what, std::initializer_list<const char*> allowed) const;
  void expect_object(const char* what, const std::vector<std::string>& allowed) const;
  // The keys of an object, in the file's order ("comment" left out).
  std::vector<std::string> keys() const;
  bool has(const char* key) const;
  JsonNode operator[](const char* key) const;  // a missing child when absent
  // An array (of any length when min == 0); its elements are index(i).
  size_t array_size(const char* what, size_t min = 0) const;
  JsonNode index(size_t i) const;

  // Scalars. Each throws when missing; the opt_ forms return def when missing.
  double number() const;
  float positive() const;
  float non_negative() const;
  float in_range(float lo, float hi) const;
  uint32_t count(uint32_t lo, uint32_t hi) const;
  bool boolean() const;
  std::string string() const;
  // One of `choices`; returns its index.
  size_t choice(std::initializer_list<const char*> choices) const;
  size_t choice(const std::vector<std::string>& choices) const;
  sph_vec3 vec3() const;
  sph_vec3 direction() const;  // a vec3 that is not zero

  float opt_number(float def) const { return missing() ? def : static_cast<float>(number()); }
  float opt_positive(float def) const { return missing() ? def : positive(); }
  float opt_non_negative(float def) const { return missing() ? def : non_negative(); }
  float opt_in_range(float def, float lo, float hi) const { return missing() ? def : in_range(lo, hi); }
  uint32_t opt_count(uint32_t def, uint32_t lo, uint32_t hi) const { return missing() ? def : count(lo, hi); }
  bool opt_boolean(bool def) const { return missing() ? def : boolean(); }
  std::string opt_string(const std::string& def) const { return missing() ? def : string(); }
  size_t opt_choice(size_t def, std::initializer_list<const char*> choices) const {
    return missing() ? def : choice(choices);
  }
  sph_vec3 opt_vec3(sph_vec3 def) const { return missing() ? def : vec3(); }

 private:
  const nlohmann::json* value_;
  std::string path_;
};

// A number as the file would write it ("0.5", "1e-06").
std::string number_text(double value);

// "got -1", "got a string \"abc\"", "got an object", ... for error messages.
std::string describe_json(const nlohmann::json& value);

}  // namespace sph_tools

#endif
