// What the FMU tests share: model descriptions of FMI 2.0 and 3.0 with every variable type, and
// FMU archives written with libzip (entries given by name and bytes, or as symbolic links).
#pragma once

#include <zip.h>

#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace cosmic::test {

// FMI 2.0: every type (Real with a unit from its declared type, Integer, Boolean, String, Enumeration),
// every causality of 2.0; the Integer shares valueReference 1 with the Real (allowed: another fmi2Get).
inline const char* const kFmi2Description = R"(<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="Plant" guid="{8c4e810f-3df3-4a00-8276-176fa3c9f000}">
  <CoSimulation modelIdentifier="Plant" canHandleVariableCommunicationStepSize="true"/>
  <TypeDefinitions>
    <SimpleType name="Speed"><Real unit="m/s" min="-20" max="20"/></SimpleType>
    <SimpleType name="Mode"><Enumeration><Item name="off" value="1"/><Item name="on" value="2"/></Enumeration></SimpleType>
  </TypeDefinitions>
  <DefaultExperiment startTime="0" stopTime="10" tolerance="1e-6" stepSize="0.01"/>
  <ModelVariables>
    <ScalarVariable name="time" valueReference="0" causality="independent"><Real/></ScalarVariable>
    <ScalarVariable name="u" valueReference="1" causality="input"><Real declaredType="Speed" start="0"/></ScalarVariable>
    <ScalarVariable name="y" valueReference="2" causality="output"><Real unit="m/s"/></ScalarVariable>
    <ScalarVariable name="count" valueReference="1" causality="output"><Integer min="0" max="200"/></ScalarVariable>
    <ScalarVariable name="ready" valueReference="0" causality="output"><Boolean/></ScalarVariable>
    <ScalarVariable name="label" valueReference="0" causality="parameter" variability="fixed"><String start="plant"/></ScalarVariable>
    <ScalarVariable name="mode" valueReference="3" causality="input"><Enumeration declaredType="Mode" start="1"/></ScalarVariable>
    <ScalarVariable name="gain" valueReference="3" causality="parameter" variability="tunable"><Real start="2" min="0" max="10"/></ScalarVariable>
    <ScalarVariable name="x" valueReference="4"><Real/></ScalarVariable>
    <ScalarVariable name="twice" valueReference="5" causality="calculatedParameter" variability="fixed"><Real/></ScalarVariable>
  </ModelVariables>
  <ModelStructure/>
</fmiModelDescription>
)";

// FMI 3.0: every type of 3.0, an array, an alias, a structural parameter.
inline const char* const kFmi3Description = R"(<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="3.0" modelName="Every" instantiationToken="{every}">
  <CoSimulation modelIdentifier="Every" canHandleVariableCommunicationStepSize="true" hasEventMode="true" fixedInternalStepSize="0.001"/>
  <TypeDefinitions>
    <Float64Type name="Angle" unit="rad"/>
    <EnumerationType name="Gear"><Item name="park" value="0"/><Item name="drive" value="1"/><Item name="reverse" value="-1"/></EnumerationType>
  </TypeDefinitions>
  <DefaultExperiment stepSize="0.005"/>
  <ModelVariables>
    <Float64 name="time" valueReference="0" causality="independent" variability="continuous"/>
    <Float32 name="f32" valueReference="1" causality="input" start="0.5"/>
    <Float64 name="angle" valueReference="2" causality="output" declaredType="Angle">
      <Alias name="heading"/>
    </Float64>
    <Int8 name="i8" valueReference="3" causality="input"/>
    <UInt8 name="u8" valueReference="4" causality="output"/>
    <Int16 name="i16" valueReference="5" causality="output"/>
    <UInt16 name="u16" valueReference="6" causality="output"/>
    <Int32 name="i32" valueReference="7" causality="output"/>
    <UInt32 name="u32" valueReference="8" causality="output"/>
    <Int64 name="i64" valueReference="9" causality="input"/>
    <UInt64 name="u64" valueReference="10" causality="output" start="18446744073709551615"/>
    <Boolean name="flag" valueReference="11" causality="input" start="false"/>
    <String name="text" valueReference="12" causality="parameter" variability="fixed"><Start value="hello world"/></String>
    <Binary name="blob" valueReference="13" causality="output"/>
    <Enumeration name="gear" valueReference="14" causality="output" declaredType="Gear" start="0"/>
    <Clock name="tick" valueReference="15" causality="input"/>
    <UInt64 name="n" valueReference="16" causality="structuralParameter" variability="fixed" start="3"/>
    <Float64 name="vector" valueReference="17" causality="output" start="1 2 3"><Dimension valueReference="16"/></Float64>
  </ModelVariables>
  <ModelStructure/>
</fmiModelDescription>
)";

struct ZipEntry {
  std::string name;
  std::string bytes;
  bool symlink = false;  // a Unix symbolic link to `bytes`
};

// Writes `entries` as a zip archive at `path`; false when libzip refused.
inline bool write_zip(const std::string& path, const std::vector<ZipEntry>& entries) {
  int code = 0;
  zip_t* archive = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &code);
  if (archive == nullptr) return false;
  for (const ZipEntry& e : entries) {
    zip_source_t* source = zip_source_buffer(archive, e.bytes.data(), e.bytes.size(), 0);
    const zip_int64_t index = source ? zip_file_add(archive, e.name.c_str(), source, ZIP_FL_ENC_UTF_8) : -1;
    if (index < 0) {
      zip_source_free(source);
      zip_discard(archive);
      return false;
    }
    if (e.symlink) {
      const zip_uint32_t mode = 0120777u << 16;  // S_IFLNK | 0777
      zip_file_set_external_attributes(archive, static_cast<zip_uint64_t>(index), 0, ZIP_OPSYS_UNIX, mode);
    }
  }
  return zip_close(archive) == 0;
}

inline std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace cosmic::test
