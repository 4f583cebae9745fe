//! A validator for the subset of JSON Schema (2020-12) that
//! `src/verify/summary.schema.json` uses: `type` (one or a list), `required`,
//! `properties`, `additionalProperties: false`, `items`, `enum`, `anyOf` and local
//! `$ref`s to `#/$defs/NAME`. Returns every violation with its JSON path, so a test names
//! what departs from the schema.

use serde_json::Value;

/// The schema of `summary.json`, as shipped in the repository.
pub fn summary_schema() -> Value {
    let path = super::manifest_dir().join("src/verify/summary.schema.json");
    serde_json::from_str(&std::fs::read_to_string(&path).expect("summary.schema.json"))
        .expect("summary.schema.json parses")
}

/// The violations of `schema` (the root, whose `$defs` resolve `$ref`s) by `value`.
pub fn violations(schema: &Value, value: &Value) -> Vec<String> {
    let mut out = Vec::new();
    check(schema, schema, value, "$", &mut out);
    out
}

fn type_matches(t: &str, v: &Value) -> bool {
    match t {
        "object" => v.is_object(),
        "array" => v.is_array(),
        "string" => v.is_string(),
        "boolean" => v.is_boolean(),
        "null" => v.is_null(),
        "number" => v.is_number(),
        "integer" => v.is_u64() || v.is_i64(),
        _ => false,
    }
}

fn check(root: &Value, s: &Value, v: &Value, path: &str, out: &mut Vec<String>) {
    if let Some(r) = s.get("$ref").and_then(Value::as_str) {
        let name = r.strip_prefix("#/$defs/").expect("local $ref");
        return check(root, &root["$defs"][name], v, path, out);
    }
    if let Some(any) = s.get("anyOf").and_then(Value::as_array) {
        if !any.iter().any(|a| {
            let mut o = Vec::new();
            check(root, a, v, path, &mut o);
            o.is_empty()
        }) {
            out.push(format!("{path}: matches none of anyOf"));
        }
        return;
    }
    if let Some(t) = s.get("type") {
        let types: Vec<&str> = match t {
            Value::String(t) => vec![t.as_str()],
            Value::Array(ts) => ts.iter().filter_map(Value::as_str).collect(),
            _ => vec![],
        };
        if !types.iter().any(|t| type_matches(t, v)) {
            out.push(format!("{path}: {v} is not of type {t}"));
            return;
        }
    }
    if let Some(allowed) = s.get("enum").and_then(Value::as_array)
        && !allowed.contains(v)
    {
        out.push(format!("{path}: {v} is not one of {allowed:?}"));
    }
    if let Some(obj) = v.as_object() {
        let props = s.get("properties").and_then(Value::as_object);
        for key in s
            .get("required")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
        {
            let key = key.as_str().unwrap_or_default();
            if !obj.contains_key(key) {
                out.push(format!("{path}: required key {key} missing"));
            }
        }
        for (key, value) in obj {
            match props.and_then(|p| p.get(key)) {
                Some(ps) => check(root, ps, value, &format!("{path}.{key}"), out),
                None if s.get("additionalProperties") == Some(&Value::Bool(false)) => {
                    out.push(format!("{path}: key {key} not in the schema"));
                }
                None => {}
            }
        }
    }
    if let (Some(items), Some(arr)) = (s.get("items"), v.as_array()) {
        for (i, item) in arr.iter().enumerate() {
            check(root, items, item, &format!("{path}[{i}]"), out);
        }
    }
}
