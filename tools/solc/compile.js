#!/usr/bin/env node
// Compiles contracts/InformationMarket.sol, and the modules and interfaces it imports from contracts/,
// with the solc-js version pinned in package.json and writes the ABI + bytecode artifact that the
// Python package ships (src/infomarket/evm/artifacts/), so that nothing on the Python side ever needs
// Node or a compiler.
//
// Usage: node tools/solc/compile.js [--contracts DIR] [--out FILE] [--layout FILE] [--allow-warnings]
//   --contracts  directory that stands for contracts/ (default: the checkout's); used by the mutation
//                check (tests/evm/mutation.py) to compile a patched copy under the same source names.
//   --out        where to write the artifact (default: the committed one).
//   --layout     also write the storage layout (slot, offset and type of every state variable), which
//                must not move when the contract's modules are rearranged.
//   --allow-warnings  do not fail on compiler warnings (only for such patched copies).
// Imports are resolved inside the contracts directory only (relative paths, as solc resolves them
// against the importing unit's name); an import from anywhere else is an error, so the artifact
// depends on nothing outside the checkout. The output is deterministic (same sources and compiler, same
// bytes), which is what lets a test recompile and compare against the committed file.
'use strict';

const crypto = require('crypto');
const fs = require('fs');
const path = require('path');
const solc = require('solc');

const ROOT = path.resolve(__dirname, '..', '..');
const PREFIX = 'contracts/';
const SOURCE_NAME = `${PREFIX}InformationMarket.sol`;
const CONTRACT = 'InformationMarket';
const SETTINGS = {
  optimizer: { enabled: true, runs: 200 },
  evmVersion: 'cancun',
  viaIR: true,
  outputSelection: { '*': { '*': ['abi', 'evm.bytecode.object', 'evm.deployedBytecode.object'] } },
};

function usage(message) {
  process.stderr.write(
    `usage: compile.js [--contracts DIR] [--out FILE] [--layout FILE] [--allow-warnings] (${message})\n`);
  process.exit(2);
}

function parseArgs(argv) {
  const args = {
    contracts: path.join(ROOT, 'contracts'),
    out: path.join(ROOT, 'src', 'infomarket', 'evm', 'artifacts', `${CONTRACT}.json`),
    layout: null,
    allowWarnings: false,
  };
  for (let i = 0; i < argv.length; i += 1) {
    if (argv[i] === '--allow-warnings') {
      args.allowWarnings = true;
      continue;
    }
    const key = argv[i].replace(/^--/, '');
    if (!['contracts', 'out', 'layout'].includes(key) || i + 1 >= argv.length) usage(`bad argument ${argv[i]}`);
    args[key] = path.resolve(argv[i + 1]);
    i += 1;
  }
  if (!fs.existsSync(path.join(args.contracts, 'InformationMarket.sol'))) {
    usage(`no InformationMarket.sol in ${args.contracts}`);
  }
  return args;
}

// Reads a source unit named contracts/... from the contracts directory; refuses every other name.
function reader(dir) {
  return (name) => {
    const rel = name.startsWith(PREFIX) ? path.normalize(name.slice(PREFIX.length)) : null;
    if (rel === null || rel.startsWith('..') || path.isAbsolute(rel)) {
      return { error: `${name}: only files under ${PREFIX} may be imported` };
    }
    const file = path.join(dir, rel);
    if (!fs.existsSync(file)) return { error: `${name}: no such file in ${dir}` };
    return { contents: fs.readFileSync(file, 'utf8') };
  };
}

function main() {
  const args = parseArgs(process.argv.slice(2));
  const read = reader(args.contracts);
  const settings = JSON.parse(JSON.stringify(SETTINGS));
  if (args.layout) settings.outputSelection['*']['*'].push('storageLayout');
  const input = {
    language: 'Solidity',
    sources: { [SOURCE_NAME]: { content: read(SOURCE_NAME).contents } },
    settings,
  };
  const contents = {};
  const findImports = (name) => {
    const found = read(name);
    if (found.contents !== undefined) contents[name] = found.contents;
    return found;
  };
  contents[SOURCE_NAME] = input.sources[SOURCE_NAME].content;
  const output = JSON.parse(solc.compile(JSON.stringify(input), { import: findImports }));
  const problems = (output.errors || []).filter((e) => e.severity !== 'info');
  for (const e of problems) process.stderr.write(`${e.formattedMessage}\n`);
  // Warnings fail too: a clean compile is part of what the committed artifact promises.
  if (problems.some((e) => e.severity === 'error' || !args.allowWarnings)) process.exit(1);
  const compiled = output.contracts[SOURCE_NAME][CONTRACT];
  // Every unit the compiler read, by name, with its hash: a cheap staleness check needs no compiler.
  const sources = {};
  for (const name of Object.keys(output.sources).sort()) {
    sources[name] = crypto.createHash('sha256').update(contents[name]).digest('hex');
  }
  const artifact = {
    contractName: CONTRACT,
    sourceName: SOURCE_NAME,
    sources,
    compiler: { name: 'solc-js', version: solc.version(), settings: SETTINGS },
    abi: compiled.abi,
    bytecode: `0x${compiled.evm.bytecode.object}`,
    deployedBytecode: `0x${compiled.evm.deployedBytecode.object}`,
  };
  fs.mkdirSync(path.dirname(args.out), { recursive: true });
  fs.writeFileSync(args.out, `${JSON.stringify(artifact, null, 1)}\n`);
  process.stdout.write(`wrote ${path.relative(process.cwd(), args.out)} (${solc.version()})\n`);
  if (args.layout) {
    // Labels, slots, offsets and type names only: the AST ids solc also reports change with any edit.
    const { storage, types } = compiled.storageLayout;
    const layout = storage.map((v) => ({
      label: v.label, slot: v.slot, offset: v.offset, type: types[v.type].label,
      bytes: types[v.type].numberOfBytes,
    }));
    fs.writeFileSync(args.layout, `${JSON.stringify(layout, null, 1)}\n`);
  }
}

main();
