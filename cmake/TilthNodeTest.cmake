# Tests run by Node.js against npm packages pinned in a folder's package-lock.json (the
# independent MCAP reader, the Kubernetes API's schemas).
find_program(NODE node REQUIRED)
find_program(NPM npm REQUIRED)

# tilth_node_test(NAME DIR SCRIPT LABELS...): `node --test SCRIPT` in DIR, after `npm ci`
# when DIR's node_modules is missing or older than its lock file. The tests of one DIR
# share a resource lock, so that two never install at once. The environment has
# TILTH_SOURCE_DIR; append more with set_property(TEST ... APPEND PROPERTY ENVIRONMENT).
function(tilth_node_test name dir script)
  string(MAKE_C_IDENTIFIER "npm_${dir}" lock)
  add_test(NAME ${name}
    COMMAND bash -c "set -e; cd '${dir}'; [ node_modules/.package-lock.json -nt package-lock.json ] || '${NPM}' ci --no-audit --no-fund; '${NODE}' --test ${script}")
  set_tests_properties(${name} PROPERTIES LABELS "${ARGN}" RESOURCE_LOCK ${lock}
    ENVIRONMENT "TILTH_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
endfunction()
