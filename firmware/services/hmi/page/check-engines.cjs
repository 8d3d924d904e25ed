// Refuses a Node.js that some package pinned by the lock file does not support (its `engines.node`),
// naming the package, its requirement and the Node found. Run before the page is built and before the
// browser test: npm itself only warns (EBADENGINE) and installs anyway, and the failure then comes
// later and far from its cause (Playwright 1.62+ on Debian 12's Node 18: issue 17).
//
//   node check-engines.cjs PACKAGE-LOCK.JSON
// (NODE_PATH must reach the page's node_modules, for semver: the range grammar is npm's own.)
'use strict';
const fs = require('fs');

function readLock(lockPath) {
  let text;
  try {
    text = fs.readFileSync(lockPath, 'utf8');
  } catch (error) {
    throw new Error(`${lockPath}: cannot read the lock file (${error.code || error.message})`);
  }
  let lock;
  try {
    lock = JSON.parse(text);
  } catch (error) {
    throw new Error(`${lockPath}: not JSON (${error.message})`);
  }
  if (lock === null || typeof lock !== 'object' || lock.packages === null || typeof lock.packages !== 'object') {
    throw new Error(`${lockPath}: expected a lock file of lockfileVersion 2 or 3, with a "packages" map`);
  }
  return lock;
}

// Every package in the lock whose engines.node the running Node does not satisfy, as messages.
function engineProblems(lockPath, nodeVersion, semver) {
  const lock = readLock(lockPath);
  const problems = [];
  for (const [location, entry] of Object.entries(lock.packages)) {
    const range = entry && entry.engines && entry.engines.node;
    if (range === undefined) continue;
    const name = location === '' ? (lock.name || 'the page itself') : location.replace(/^.*node_modules\//, '');
    const what = `${name} ${entry.version || ''}`.trim();
    if (typeof range !== 'string' || semver.validRange(range) === null) {
      problems.push(`${lockPath}: ${what}: engines.node ${JSON.stringify(range)} is not a version range`);
    } else if (!semver.satisfies(nodeVersion, range, { includePrerelease: true })) {
      problems.push(`${what} (pinned by ${lockPath}) requires Node ${range}; this Node is ${nodeVersion}`);
    }
  }
  return problems;
}

function main() {
  const lockPath = process.argv[2];
  if (!lockPath || process.argv.length > 3) {
    console.error('usage: node check-engines.cjs PACKAGE-LOCK.JSON');
    process.exit(2);
  }
  let semver;
  try {
    semver = require('semver');
  } catch (error) {
    console.error('check-engines: semver not found: NODE_PATH must reach the page\'s node_modules (npm ci first)');
    process.exit(2);
  }
  let problems;
  try {
    problems = engineProblems(lockPath, process.version, semver);
  } catch (error) {
    console.error(`check-engines: ${error.message}`);
    process.exit(2);
  }
  if (problems.length > 0) {
    for (const problem of problems) console.error(`check-engines: ${problem} (${process.execPath})`);
    console.error('check-engines: pin versions whose engines accept this Node, or run a Node they accept '
      + '(README: the operator display)');
    process.exit(1);
  }
  console.log(`check-engines: Node ${process.version} satisfies every package in ${lockPath}`);
}

main();
