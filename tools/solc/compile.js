#!/usr/bin/env node
// Compiles contracts/InformationMarket.sol with the solc-js version pinned in package.json and writes
// the ABI + bytecode artifact that the Python package ships (src/infomarket/evm/artifacts/), so that
// nothing on the Python side ever needs Node or a compiler.
//
// Usage: node tools/solc/compile.js [--source FILE] [--out FILE] [--allow-warnings]
//   --source  Solidity file to compile (default: contracts/InformationMarket.sol); used by the
//             mutation check (tests/evm/mutation.py) to compile a patched copy under the same name.
//   --out     where to write the artifact (default: the committed one).
//   --allow-warnings  do not fail on compiler warnings (only for such patched copies).
// The output is deterministic (same source and compiler, same bytes), which is what lets a test
// recompile and compare against the committed file.
'use strict';

const crypto = require('crypto');
const fs = require('fs');
const path = require('path');
const solc = require('solc');

const ROOT = path.resolve(__dirname, '..', '..');
const SOURCE_NAME = 'contracts/InformationMarket.sol';
const CONTRACT = 'InformationMarket';
const SETTINGS = {
  optimizer: { enabled: true, runs: 200 },
  evmVersion: 'cancun',
  viaIR: true,
  outputSelection: { '*': { '*': ['abi', 'evm.bytecode.object', 'evm.deployedBytecode.object'] } },
};

function parseArgs(argv) {
  const args = {
    source: path.join(ROOT, SOURCE_NAME),
    out: path.join(ROOT, 'src', 'infomarket', 'evm', 'artifacts', `${CONTRACT}.json`),
    allowWarnings: false,
  };
  for (let i = 0; i < argv.length; i += 1) {
    if (argv[i] === '--allow-warnings') {
      args.allowWarnings = true;
      continue;
    }
    const key = argv[i].replace(/^--/, '');
    if (!['source', 'out'].includes(key) || i + 1 >= argv.length) {
      process.stderr.write(`usage: compile.js [--source FILE] [--out FILE] [--allow-warnings] (bad argument ${argv[i]})\n`);
      process.exit(2);
    }
    args[key] = path.resolve(argv[i + 1]);
    i += 1;
  }
  return args;
}

function main() {
  const args = parseArgs(process.argv.slice(2));
  const content = fs.readFileSync(args.source, 'utf8');
  const input = { language: 'Solidity', sources: { [SOURCE_NAME]: { content } }, settings: SETTINGS };
  const output = JSON.parse(solc.compile(JSON.stringify(input)));
  const problems = (output.errors || []).filter((e) => e.severity !== 'info');
  for (const e of problems) process.stderr.write(`${e.formattedMessage}\n`);
  // Warnings fail too: a clean compile is part of what the committed artifact promises.
  if (problems.some((e) => e.severity === 'error' || !args.allowWarnings)) process.exit(1);
  const compiled = output.contracts[SOURCE_NAME][CONTRACT];
  const artifact = {
    contractName: CONTRACT,
    sourceName: SOURCE_NAME,
    sourceSha256: crypto.createHash('sha256').update(content).digest('hex'),
    compiler: { name: 'solc-js', version: solc.version(), settings: SETTINGS },
    abi: compiled.abi,
    bytecode: `0x${compiled.evm.bytecode.object}`,
    deployedBytecode: `0x${compiled.evm.deployedBytecode.object}`,
  };
  fs.mkdirSync(path.dirname(args.out), { recursive: true });
  fs.writeFileSync(args.out, `${JSON.stringify(artifact, null, 1)}\n`);
  process.stdout.write(`wrote ${path.relative(process.cwd(), args.out)} (${solc.version()})\n`);
}

main();
