// SPDX-License-Identifier: MIT
#include "json_node.h"

#include <cmath>
#include <cstdio>
#include <limits>

#include "scene_error.h"

namespace sph_tools {

std::string number_text(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

std::string describe_json(const nlohmann::json& value) {
  switch (value.type()) {
    case nlohmann::json::value_t::null:
      return "null";
    case nlohmann::json::value_t::boolean:
      return value.get<bool>() ? "true" : "false";
    case nlohmann::json::value_t::string: {
      std::string s = value.get<std::string>();
      if (s.size() > 40) s = s.substr(0, 37) + "...";
      return "the string \"" + s + "\"";
    }
    case nlohmann::json::value_t::object:
      return "an object";
    case nlohmann::json::value_t::array:
      return "an array of " + std::to_string(value.size());
    default: {
      std::string s = value.dump();
      return s.size() > 40 ? s.substr(0, 37) + "..." : s;
    }
  }
}

void JsonNode::fail(const std::string& expected) const {
  if (missing()) throw SceneError(path_, "missing (expected " + expected + ")");
  throw SceneError(path_, "expected " + expected + ", got " + describe_json(*value_));
}

void JsonNode::expect_object(const char* what, std::initializer_list<const char*> allowed) const {
  expect_object(what, std::vector<std::string>(allowed.begin(), allowed.end()));
}

void JsonNode::expect_object(const char* what, const std::vector<std::string>& allowed) const {
  if (missing() || !value_->is_object()) fail(std::string(what) + " (an object)");
  for (auto it = value_->begin(); it != value_->end(); ++it) {
    if (it.key() == "comment") {
      // A note for people, so a string (docs/scenes.md); anything else is most likely a key
      // that lost its name.
      if (!it.value().is_string()) (*this)["comment"].fail("a string (a comment)");
      continue;
    }
    bool known = false;
    for (const std::string& key : allowed) known = known || it.key() == key;
    if (!known) {
      std::string list;
      for (const std::string& key : allowed) list += (list.empty() ? "" : ", ") + key;
      const std::string child = path_.empty() ? it.key() : path_ + "." + it.key();
      throw SceneError(child,
                       "unknown field; " + std::string(what) + " takes " + list + " (and \"comment\")");
    }
  }
}

std::vector<std::string> JsonNode::keys() const {
  std::vector<std::string> out;
  if (missing() || !value_->is_object()) return out;
  for (auto it = value_->begin(); it != value_->end(); ++it)
    if (it.key() != "comment") out.push_back(it.key());
  return out;
}

bool JsonNode::has(const char* key) const {
  return !missing() && value_->is_object() && value_->contains(key);
}

JsonNode JsonNode::operator[](const char* key) const {
  const std::string child = path_.empty() ? key : path_ + "." + key;
  if (!has(key)) return JsonNode(nullptr, child);
  return JsonNode(&(*value_)[key], child);
}

size_t JsonNode::array_size(const char* what, size_t min) const {
  if (missing() || !value_->is_array()) fail(std::string(what) + " (an array)");
  if (value_->size() < min) fail(std::string(what) + " (an array of at least " + std::to_string(min) + ")");
  return value_->size();
}

JsonNode JsonNode::index(size_t i) const {
  return JsonNode(&(*value_)[i], path_ + "[" + std::to_string(i) + "]");
}

double JsonNode::number() const {
  if (missing() || !value_->is_number()) fail("a number");
  const double v = value_->get<double>();
  if (!std::isfinite(v) || std::fabs(v) > std::numeric_limits<float>::max()) fail("a finite number");
  return v;
}

float JsonNode::positive() const {
  if (missing() || !value_->is_number()) fail("a positive number");
  const double v = value_->get<double>();
  if (!(v > 0.0) || !std::isfinite(v) || v > std::numeric_limits<float>::max() ||
      static_cast<float>(v) <= 0.0f)
    fail("a positive number");
  return static_cast<float>(v);
}

float JsonNode::non_negative() const {
  if (missing() || !value_->is_number()) fail("a number >= 0");
  const double v = value_->get<double>();
  if (!(v >= 0.0) || !std::isfinite(v) || v > std::numeric_limits<float>::max()) fail("a number >= 0");
  return static_cast<float>(v);
}

float JsonNode::in_range(float lo, float hi) const {
  const std::string expected = "a number in [" + number_text(lo) + ", " + number_text(hi) + "]";
  if (missing() || !value_->is_number()) fail(expected);
  const double v = value_->get<double>();
  if (!(v >= lo && v <= hi)) fail(expected);
  return static_cast<float>(v);
}

uint32_t JsonNode::count(uint32_t lo, uint32_t hi) const {
  const std::string expected = hi == std::numeric_limits<uint32_t>::max()
                                   ? "an integer >= " + std::to_string(lo)
                                   : "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  if (missing() || !value_->is_number()) fail(expected);
  const double v = value_->get<double>();
  // "an integer >= 1" would be a riddle for 4294967296: name the bound it passed.
  if (v > hi && std::floor(v) == v)
    fail("an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  if (!(v >= lo && v <= hi) || std::floor(v) != v) fail(expected);
  return static_cast<uint32_t>(v);
}

bool JsonNode::boolean() const {
  if (missing() || !value_->is_boolean()) fail("true or false");
  return value_->get<bool>();
}

std::string JsonNode::string() const {
  if (missing() || !value_->is_string()) fail("a string");
  return value_->get<std::string>();
}

size_t JsonNode::choice(std::initializer_list<const char*> choices) const {
  return choice(std::vector<std::string>(choices.begin(), choices.end()));
}

size_t JsonNode::choice(const std::vector<std::string>& choices) const {
  std::string list;
  size_t n = 0;
  for (const std::string& c : choices) {
    list += std::string(n == 0 ? "" : n + 1 == choices.size() ? " or " : ", ") + "\"" + c + "\"";
    ++n;
  }
  if (missing() || !value_->is_string()) fail(list);
  const std::string s = value_->get<std::string>();
  for (size_t i = 0; i < choices.size(); ++i)
    if (s == choices[i]) return i;
  fail(list);
}

sph_vec3 JsonNode::vec3() const {
  const char* expected = "an array of 3 numbers [x, y, z]";
  if (missing() || !value_->is_array() || value_->size() != 3) fail(expected);
  float v[3];
  for (size_t i = 0; i < 3; ++i) v[i] = static_cast<float>(index(i).number());
  return sph_vec3{v[0], v[1], v[2]};
}

sph_vec3 JsonNode::direction() const {
  const sph_vec3 v = vec3();
  if (v.x == 0.0f && v.y == 0.0f && v.z == 0.0f) fail("a non-zero vector [x, y, z]");
  return v;
}

}  // namespace sph_tools
