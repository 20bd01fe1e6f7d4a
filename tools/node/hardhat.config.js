module.exports = { networks: { hardhat: { hardfork: "cancun", chainId: 31337, blockGasLimit: 30000000, accounts: { accountsBalance: "1000000000000000000000000000" } } } };
