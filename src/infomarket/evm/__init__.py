"""The information market on an Ethereum chain (docs/model.md §9).

``contracts/InformationMarket.sol`` enforces the market's rules; this package is its client side:

- ``units``: the fixed-point encodings of amounts, directions and positions;
- ``protocol``: the off-chain light contract (EIP-712 offer and acceptance, signed by each robot's key);
- ``market``: deploying the contract and sending each robot's transactions (in-process EVM or RPC);
- ``evm_replay``: running a simulator event log through the contract and comparing the balances;
- ``gasreport``: the gas table in docs/gas.md;  ``cli``: ``infomarket chain demo``.

Nothing here needs Node or a compiler: the ABI and bytecode are in ``artifacts/``. Importing this
package is cheap; web3 is only loaded by the modules that talk to a chain (the ``chain`` extra).
"""
