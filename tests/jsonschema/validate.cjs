// node validate.cjs NPM_DIR CASES_DIR: holds the schemas cosmic::json_schema() wrote (CASES_DIR/
// NAME.schema.json, by cosmic-json-schema-cases) against ajv, a JSON Schema validator we did not
// write, in its draft 2020-12 flavour and strict mode (a keyword it does not know, a union type it
// would ignore, a `required` naming no property ... fail the compilation):
//   - every event JsonRepresentation wrote (NAME.events.jsonl) validates against its schema;
//   - documents made invalid by hand from a valid event of every_kind are refused, each for the
//     reason it was made for, so the schema is not merely permissive.
// ajv is loaded from NPM_DIR/node_modules (npm ci there, run_ajv.sh). Exit status 0 when all holds.
"use strict";
const fs = require("fs");
const path = require("path");
const { createRequire } = require("module");

const [npmDir, casesDir] = process.argv.slice(2);
const Ajv2020 = createRequire(path.join(path.resolve(npmDir), "package.json"))("ajv/dist/2020");

const kExpectedCases = ["diagnostics", "every_kind", "nested_conditional", "status", "strings"];
const kLeastEventsPerCase = 100;

let failures = 0;
function fail(message) {
  console.error("FAIL " + message);
  failures += 1;
}

function compile(name) {
  const schema = JSON.parse(fs.readFileSync(path.join(casesDir, name + ".schema.json"), "utf8"));
  if (schema.$schema !== "https://json-schema.org/draft/2020-12/schema") fail(`${name}: $schema is ${schema.$schema}`);
  if (schema.title !== name) fail(`${name}: title is ${schema.title}`);
  const ajv = new Ajv2020({ strict: true, allErrors: true });
  return ajv.compile(schema);
}

function validateEvents(name, validate) {
  const lines = fs.readFileSync(path.join(casesDir, name + ".events.jsonl"), "utf8").split("\n").filter((l) => l);
  if (lines.length < kLeastEventsPerCase) fail(`${name}: only ${lines.length} events`);
  lines.forEach((line, index) => {
    if (!validate(JSON.parse(line))) {
      fail(`${name} event ${index} does not validate: ${line}\n  ${JSON.stringify(validate.errors)}`);
    }
  });
  return lines;
}

// A valid every_kind event with mode 0 (dtc carried, the others of mode 1 and 2 left out).
function modeZeroEvent(lines) {
  const event = JSON.parse(lines[0]);
  for (const name of ["codes", "pressure", "note"]) delete event[name];
  return Object.assign(event, { mode: 0, dtc: 7, i8: 5, u16: 9, state: "RUN", label: "ok",
    ranges: [0, 1, 2, 3], track: [1], f32: 1.5 });
}

// Each made from a valid event by one change; [what is wrong, the change, the keyword that refuses].
const kInvalid = [
  ["a required field missing", (e) => delete e.flag, "required"],
  ["a property the type does not have", (e) => (e.extra = 1), "additionalProperties"],
  ["an int8 above 127", (e) => (e.i8 = 128), "maximum"],
  ["a uint16 below 0", (e) => (e.u16 = -1), "minimum"],
  ["an integer field with a fraction", (e) => (e.i8 = 1.5), "type"],
  ["a float32 beyond its finite limits", (e) => (e.f32 = 3.5e38), "maximum"],
  ["a float as a string", (e) => (e.f32 = "1.5"), "type"],
  ["a fixed array one too long", (e) => e.ranges.push(4), "maxItems"],
  ["a fixed array one too short", (e) => e.ranges.pop(), "minItems"],
  ["a sequence over its bound", (e) => (e.track = [1, 2, 3, 4]), "maxItems"],
  ["a string over its bound", (e) => (e.label = "123456789"), "maxLength"],
  ["a name the enumeration does not have", (e) => (e.state = "BOGUS"), "enum"],
  ["a named value as its number", (e) => (e.state = 1), "not"],
  ["a nested record missing a field", (e) => delete e.pose.heading, "required"],
  ["a conditional field missing while selected", (e) => delete e.dtc, "required"],
  ["a conditional field present while not selected", (e) => (e.mode = 1), "false schema"],
  ["a conditional field of another selector value", (e) => (e.pressure = 1), "false schema"],
];

function checkInvalid(validate, lines) {
  const base = modeZeroEvent(lines);
  if (!validate(base)) fail(`the hand-made valid event does not validate: ${JSON.stringify(validate.errors)}`);
  for (const [what, change, keyword] of kInvalid) {
    const event = structuredClone(base);
    change(event);
    if (validate(event)) {
      fail(`every_kind accepts ${what}: ${JSON.stringify(event)}`);
    } else if (!validate.errors.some((e) => e.keyword === keyword)) {
      fail(`every_kind refuses ${what}, but not by ${keyword}: ${JSON.stringify(validate.errors)}`);
    }
  }
}

const found = fs.readdirSync(casesDir).filter((f) => f.endsWith(".schema.json")).map((f) => f.replace(".schema.json", ""));
if (JSON.stringify(found.sort()) !== JSON.stringify(kExpectedCases)) fail(`cases ${found} are not ${kExpectedCases}`);
let events = 0;
for (const name of kExpectedCases) {
  try {
    const validate = compile(name);
    const lines = validateEvents(name, validate);
    events += lines.length;
    if (name === "every_kind") checkInvalid(validate, lines);
  } catch (error) {
    fail(`${name}: ${error.message}`);
  }
}
console.log(`ajv ${require(createRequire(path.join(path.resolve(npmDir), "package.json")).resolve("ajv/package.json")).version}: ` +
  `${kExpectedCases.length} schemas, ${events} events, ${kInvalid.length} invalid documents, ${failures} failures`);
process.exit(failures === 0 ? 0 : 1);
