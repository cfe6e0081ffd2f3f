// The Kubernetes manifests of deploy/fleet/kubernetes against the Kubernetes API's own
// OpenAPI schemas (kubernetes-models, generated from the API's OpenAPI documents and
// compiled with ajv): every document of every file validates as its apiVersion and kind;
// and the same check refuses the mistakes a hand-edited manifest makes (an enum value
// misspelt, a count quoted, a required field gone, a wrong type), naming the field.
// Unknown keys are not in these schemas: tests/ab/test_fleet_manifests.py checks them.
import assert from "node:assert/strict";
import { readdirSync, readFileSync } from "node:fs";
import path from "node:path";
import test from "node:test";

import * as batchV1 from "kubernetes-models/batch/v1";
import * as coreV1 from "kubernetes-models/v1";
import { parseAllDocuments } from "yaml";

const KUBERNETES = path.join(process.env.TILTH_SOURCE_DIR, "deploy", "fleet", "kubernetes");
const MODELS = { "batch/v1": batchV1, v1: coreV1 };

function documents(file) {
  return parseAllDocuments(readFileSync(path.join(KUBERNETES, file), "utf8")).map((document) => {
    assert.deepEqual(document.errors, [], `${file}: YAML errors`);
    return document.toJS();
  });
}

// Throws the schema's errors for `object`, as its apiVersion and kind.
function validate(object) {
  const Model = MODELS[object.apiVersion]?.[object.kind];
  assert.ok(Model, `no schema for apiVersion ${object.apiVersion}, kind ${object.kind}`);
  new Model(object).validate();
}

const MANIFESTS = readdirSync(KUBERNETES).filter((file) => file.endsWith(".yaml"));

test("the fleet has its three manifests", () => {
  assert.deepEqual(MANIFESTS.sort(), ["merge-job.yaml", "shards-job.yaml", "storage.yaml"]);
});

for (const file of MANIFESTS) {
  test(`${file} is valid against the Kubernetes API's schema`, () => {
    const objects = documents(file);
    assert.equal(objects.length, 1);
    for (const object of objects) validate(object);
  });
}

// The shards' Job changed by `edit`, expected refused with `message`.
function refused(edit, message) {
  const job = documents("shards-job.yaml")[0];
  edit(job);
  assert.throws(() => validate(job), (error) => {
    assert.match(error.message, message);
    return true;
  });
}

test("a misspelt completion mode is refused", () => {
  refused((job) => { job.spec.completionMode = "Indexd"; },
          /spec\/completionMode must be equal to one of the allowed values/);
});

test("a quoted completion count is refused", () => {
  refused((job) => { job.spec.completions = "4"; }, /spec\/completions must be integer/);
});

test("a container without a name is refused", () => {
  refused((job) => { delete job.spec.template.spec.containers[0].name; },
          /containers\/0 must have required property name/);
});

test("an environment value that is not a string is refused", () => {
  refused((job) => { job.spec.template.spec.containers[0].env[0].value = 4; },
          /env\/0\/value must be string/);
});

test("a Job without a pod template is refused", () => {
  refused((job) => { delete job.spec.template; }, /spec must have required property template/);
});
