// JSON message validation shared by the interop checks (mcap_check.mjs reads a recording, ws_client.mjs a live
// WebSocket): a message is checked against @foxglove/schemas' JSON schema when its schema name is foxglove.*,
// and against the schema text the producer itself sent (MCAP Schema record, WebSocket advertise) when there is
// one. Nothing here shares code with fieldguard's writers.
//
//   const check = makeChecker("foxglove.PointCloud", schemaText);  // throws when it cannot be set up
//   const problems = check(obj);                                    // [] when valid
import { NumericType } from "@foxglove/schemas";
import * as foxgloveJsonSchemas from "@foxglove/schemas/jsonschema.js";
import Ajv from "ajv";
import Ajv2019 from "ajv/dist/2019.js";
import Ajv2020 from "ajv/dist/2020.js";

// Ajv treats contentEncoding as an annotation only; a bytes field that is not strict base64 (RFC 4648,
// padded) would still be accepted by Node's lenient decoder but not by every viewer.
function strictBase64(ajv) {
  ajv.removeKeyword("contentEncoding");
  ajv.addKeyword({
    keyword: "contentEncoding",
    schemaType: "string",
    validate: function base64(enc, data) {
      if (enc !== "base64" || typeof data !== "string" || (data.length % 4 === 0 && /^[A-Za-z0-9+/]*={0,2}$/.test(data))) return true;
      base64.errors = [{ keyword: "contentEncoding", message: "must be standard padded base64 (RFC 4648)", params: {} }];
      return false;
    },
  });
  return ajv;
}

// The foxglove schemas declare no $schema, so Ajv's default draft-07; a producer's own schema picks its draft.
const ajvByDraft = new Map();
function ajvFor(schema) {
  const draft = schema.$schema ?? "http://json-schema.org/draft-07/schema#";
  const key = /2020-12/.test(draft) ? "2020" : /2019-09/.test(draft) ? "2019" : /draft-0[67]/.test(draft) ? "07" : undefined;
  if (!key) throw new Error(`unsupported $schema ${draft}`);
  if (!ajvByDraft.has(key)) {
    const Cls = { 2020: Ajv2020, 2019: Ajv2019, "07": Ajv }[key];
    ajvByDraft.set(key, strictBase64(new Cls({ allErrors: false, addUsedSchema: false })));
  }
  return ajvByDraft.get(key);
}
function compile(schema, what) {
  const ajv = ajvFor(schema);
  const validate = ajv.compile(schema);
  return (obj) => (validate(obj) ? undefined : `${what}: ${ajv.errorsText(validate.errors, { dataVar: "msg" })}`);
}

// Compiling is the slow part: each schema once per process, keyed by its text (a producer repeats the same
// schema on every connection or in every file split).
const compiled = new Map();
function once(key, make) {
  if (!compiled.has(key)) compiled.set(key, make());
  return compiled.get(key);
}

// What a JSON schema cannot say about a point cloud: the bytes must hold whole points and every field must lie
// inside a point.
const TYPE_SIZE = { UINT8: 1, INT8: 1, UINT16: 2, INT16: 2, UINT32: 4, INT32: 4, FLOAT32: 4, FLOAT64: 8 };
export function checkPointCloud(msg) {
  const stride = msg.point_stride;
  if (!(stride > 0)) return ["point_stride must be > 0"];
  const problems = [];
  const bytes = Buffer.from(msg.data, "base64");
  if (bytes.length % stride !== 0) problems.push(`data is ${bytes.length} bytes, not a multiple of point_stride ${stride}`);
  for (const f of msg.fields) {
    const size = TYPE_SIZE[NumericType[f.type]];
    if (size === undefined) problems.push(`field ${f.name}: numeric type ${f.type} has no size`);
    else if (f.offset + size > stride) problems.push(`field ${f.name}: offset ${f.offset} + ${size} > point_stride ${stride}`);
  }
  // Foxglove needs two coordinates to place a point.
  if (msg.fields.filter((f) => ["x", "y", "z"].includes(f.name)).length < 2) problems.push("fewer than 2 of the fields x, y, z");
  return problems;
}

// A checker for messages of schema `schemaName`: @foxglove/schemas' schema for a foxglove.* name, plus the
// producer's own schema when `embeddedSchemaText` is given (at least one of the two is needed). Throws an
// Error when the checker cannot be built (unknown foxglove name, embedded text not JSON, unsupported draft).
export function makeChecker(schemaName, embeddedSchemaText) {
  const validators = [];
  if (schemaName.startsWith("foxglove.")) {
    const upstream = foxgloveJsonSchemas[schemaName.slice("foxglove.".length)];
    if (upstream?.title !== schemaName) throw new Error(`@foxglove/schemas has no JSON schema ${schemaName}`);
    validators.push(once(`foxglove ${schemaName}`, () => compile(upstream, `schema ${schemaName} (@foxglove/schemas)`)));
  }
  if (embeddedSchemaText !== undefined && embeddedSchemaText !== "") {
    validators.push(once(`own ${schemaName} ${embeddedSchemaText}`, () => {
      let schema;
      try {
        schema = JSON.parse(embeddedSchemaText);
      } catch (e) {
        throw new Error(`schema ${schemaName} (embedded) is not JSON: ${e.message}`);
      }
      return compile(schema, `schema ${schemaName} (embedded)`);
    }));
  }
  if (validators.length === 0) throw new Error(`schema ${schemaName}: no embedded schema and not a foxglove.* name`);
  const pointCloud = schemaName === "foxglove.PointCloud";
  return (obj) => {
    const problems = validators.map((v) => v(obj)).filter(Boolean);
    // Only on a message the schemas accept: the byte checks assume its fields are there and typed.
    if (pointCloud && problems.length === 0) problems.push(...checkPointCloud(obj));
    return problems;
  };
}
