// Checks of the scene loader's error messages, shared by the loader's and the body types' tests.
#pragma once

#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "soft_body_sim/scene/scene_loader.h"

namespace soft_body_sim
{
/// Runs `load` expecting a SceneError whose message is one line that starts with "<location>: " and
/// contains every word of `reason_words`; `input` is shown if it is accepted.
inline void expectSceneError(const std::function<void()>& load, const std::string& input, const std::string& location,
                             const std::vector<std::string>& reason_words)
{
  try
  {
    load();
    ADD_FAILURE() << "accepted:\n" << input;
  }
  catch (const SceneError& e)
  {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << "not one line: " << message;
    EXPECT_EQ(message.rfind(location + ": ", 0), 0u) << "message: " << message << "\nexpected start: " << location;
    for (const std::string& word : reason_words)
      EXPECT_NE(message.find(word), std::string::npos) << "message: " << message << "\nmissing: " << word;
  }
}

/// The same for YAML text parsed as the file "bad.yaml".
inline void expectSceneError(const std::string& yaml, const std::string& location,
                             const std::vector<std::string>& reason_words)
{
  expectSceneError([&] { parseScene(yaml, "bad.yaml"); }, yaml, location, reason_words);
}

/// A scene file "<type>.yaml" holding one body `name` of `type` whose keys, from line 4 on, are `keys`.
inline SceneDef parseBodyKeys(const std::string& type, const std::string& name, const std::string& keys)
{
  return parseScene("bodies:\n  - name: " + name + "\n    type: " + type + "\n" + keys, type + ".yaml");
}

/// One row of a table of bad keys for a generated body type: `keys` (the body's keys from line 4 on)
/// must be rejected with a message starting "<location>: " that contains every word of `reason_words`.
struct BadKeys
{
  const char* name;  ///< the test's name: says what is wrong
  std::string keys;
  const char* location;  ///< "<file>:<line>: <key path>"
  std::vector<std::string> reason_words;
};

inline void PrintTo(const BadKeys& bad, std::ostream* out) { *out << bad.name; }

/// `keys` (starting at line 4 of its scene) with line `line` replaced by `text` ("" removes it).
inline std::string replaceKeyLine(const std::string& keys, int line, const std::string& text)
{
  std::string out;
  int number = 4;
  for (std::size_t start = 0; start < keys.size(); ++number)
  {
    const std::size_t end = keys.find('\n', start) + 1;
    out += number == line ? (text.empty() ? "" : text + "\n") : keys.substr(start, end - start);
    start = end;
  }
  return out;
}

}  // namespace soft_body_sim
