// SPDX-License-Identifier: MIT
pragma solidity 0.8.28;

import {IInformationMarket} from "../IInformationMarket.sol";
import {MarketStorage} from "./MarketStorage.sol";

/// @title MarketEIP712
/// @notice The EIP-712 domain of the market and the digests robots, buyers and nests sign: a deposit
/// (`Deposit(robot, trip)`) and a buyer's acceptance of an offer (`Acceptance`), so that a signature
/// is good for this contract on this chain only.
/// @dev As OpenZeppelin's EIP712: the domain separator is cached at deployment and rebuilt when the
/// chain id changes (a fork). `_recover` refuses the malleated high-s twin of a signature (EIP-2).
abstract contract MarketEIP712 is MarketStorage {
    /// @dev secp256k1 order / 2: a larger s is the malleated twin of a valid signature (EIP-2).
    uint256 internal constant _HALF_ORDER = 0x7fffffffffffffffffffffffffffffff5d576e7357a4501ddfe92f46681b20a0;

    bytes32 internal constant _DOMAIN_TYPEHASH =
        keccak256("EIP712Domain(string name,string version,uint256 chainId,address verifyingContract)");
    bytes32 internal constant _OFFER_TYPEHASH =
        keccak256("Offer(address seller,uint8 site,uint32 age,uint64 maxBlock,bytes32 pathHash)");
    bytes32 internal constant _ACCEPTANCE_TYPEHASH = keccak256(
        "Acceptance(Offer offer,address buyer,int64 sellerX,int64 sellerY,uint64 trip)"
        "Offer(address seller,uint8 site,uint32 age,uint64 maxBlock,bytes32 pathHash)"
    );
    bytes32 internal constant _DEPOSIT_TYPEHASH = keccak256("Deposit(address robot,uint64 trip)");
    bytes32 internal constant _NAME_HASH = keccak256("InformationMarket");
    bytes32 internal constant _VERSION_HASH = keccak256("4");

    uint256 internal immutable _cachedChainId;
    bytes32 internal immutable _cachedDomainSeparator;

    /// @dev Caches the domain separator of the chain the market is deployed on.
    constructor() {
        _cachedChainId = block.chainid;
        _cachedDomainSeparator = _buildDomainSeparator();
    }

    /// @inheritdoc IInformationMarket
    function depositDigest(address robot, uint64 trip) public view returns (bytes32) {
        return keccak256(
            abi.encodePacked(hex"1901", _domainSeparator(), keccak256(abi.encode(_DEPOSIT_TYPEHASH, robot, trip)))
        );
    }

    /// @inheritdoc IInformationMarket
    function acceptanceDigest(Offer calldata offer, address buyer, int64 sellerX, int64 sellerY, uint64 trip)
        public
        view
        returns (bytes32)
    {
        bytes32 offerHash = keccak256(
            abi.encode(_OFFER_TYPEHASH, offer.seller, offer.site, offer.age, offer.maxBlock, offer.pathHash)
        );
        bytes32 structHash =
            keccak256(abi.encode(_ACCEPTANCE_TYPEHASH, offerHash, buyer, sellerX, sellerY, trip));
        return keccak256(abi.encodePacked(hex"1901", _domainSeparator(), structHash));
    }

    /// @inheritdoc IInformationMarket
    function eip712Domain()
        external
        view
        returns (
            bytes1 fields,
            string memory name,
            string memory version,
            uint256 chainId,
            address verifyingContract,
            bytes32 salt,
            uint256[] memory extensions
        )
    {
        return (hex"0f", "InformationMarket", "4", block.chainid, address(this), bytes32(0), new uint256[](0));
    }

    /// @dev The signer of `digest`, refusing the malleated (high-s) twin of a signature; zero when none.
    function _recover(bytes32 digest, uint8 v, bytes32 r, bytes32 s) internal pure returns (address) {
        if (uint256(s) > _HALF_ORDER) revert InfoMarketMalleableSignature(s);
        return ecrecover(digest, v, r, s);
    }

    function _domainSeparator() internal view returns (bytes32) {
        return block.chainid == _cachedChainId ? _cachedDomainSeparator : _buildDomainSeparator();
    }

    function _buildDomainSeparator() internal view returns (bytes32) {
        return keccak256(abi.encode(_DOMAIN_TYPEHASH, _NAME_HASH, _VERSION_HASH, block.chainid, address(this)));
    }
}
