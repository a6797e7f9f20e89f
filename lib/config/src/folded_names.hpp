// Names that differ only in '-', '.' and '_' (arm-left, arm.left, arm_left) become one name
// wherever a name has to be an identifier: one C++ identifier or file in `cosmicctl gen`'s code
// (issue 22, item 5). The loader refuses the second such segment or component name with a located
// error: they exist for the model and its tools. Channels may differ so (LCM and CAN keep the
// names apart); `cosmicctl gen` refuses a model whose channels collide, and the DDS adapter two
// such channels on one segment (one topic). Internal to the config library.
#pragma once

#include <map>
#include <string>

#include "yaml_reader.hpp"

namespace cosmic::config_detail {

class FoldedNames {
 public:
  // `kind`: "segment" or "component". Reports at `name_node` when `name` folds onto an
  // earlier, different name of this kind; returns false then.
  bool add(YamlReader& reader, const YAML::Node& name_node, const std::string& path, const std::string& kind,
           const std::string& name);

 private:
  struct First {
    std::string name;
    int line = 0;
  };
  std::map<std::string, First> folded_;  // folded name -> the first name that folded onto it
};

}  // namespace cosmic::config_detail
