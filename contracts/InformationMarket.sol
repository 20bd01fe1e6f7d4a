// SPDX-License-Identifier: MIT
pragma solidity 0.8.28;

/// @title InformationMarket
/// @notice On-chain half of the robot swarm's information market (MODEL.md sections 5 and 9): sellers
/// reveal path information under a light contract the buyer signed off-chain, and the market account
/// pays every deposited item and shares part of the reward among the robot's information sellers.
/// @dev Balances live in an internal ledger of this contract's own token (9 decimals), not in an
/// ERC-20: robots never transfer tokens to each other directly, every movement of money is one of the
/// market's rules (stake, reward, share), and leaving `transfer`/`approve` out keeps the only ways to
/// move money the ones this contract audits. Invariant: the sum of all balances plus all locked stakes
/// equals `totalSupply()` (initial wealth granted plus every reward issued); rounding dust of a share
/// stays with the depositing robot, so no token is ever created or destroyed by a division.
///
/// Fixed point: token amounts in units of 1e-9 token; directions in microdegrees in [0, 360e6);
/// positions in micro arena units (signed). The similarity window theta is in microdegrees.
contract InformationMarket {
    // ------------------------------------------------------------------------------------------------
    // Types
    // ------------------------------------------------------------------------------------------------

    /// @notice How a deposit's reward share is split among the robot's sellers (MODEL.md section 5).
    /// @dev Delayed: in proportion to each seller's number of transactions; no stakes allowed.
    /// Outlier: in proportion to the number of same-site transactions within theta of each transaction,
    /// with the locked stakes added to the shared amount (staking is on when `stake() > 0`).
    enum Scheme {
        Delayed,
        Outlier
    }

    /// @notice The seller's offer, which the buyer accepts without seeing the information itself.
    /// @param seller Account that sells and must submit the reveal.
    /// @param site 0 = food, 1 = nest.
    /// @param age Age of the offered information, in simulation steps.
    /// @param maxBlock Last block in which the reveal may be included.
    /// @param pathHash `keccak256(abi.encode(x, y, direction, salt))` of the `PathInfo` to be revealed.
    struct Offer {
        address seller;
        uint8 site;
        uint32 age;
        uint64 maxBlock;
        bytes32 pathHash;
    }

    /// @notice A light contract: the offer plus the buyer's acceptance and its signature over both.
    /// @param offer The seller's offer.
    /// @param buyer Account that accepted and whose next deposit pays the seller.
    /// @param sellerX Seller's position in the buyer's frame, x, micro units (signed by the buyer).
    /// @param sellerY Same, y.
    /// @param v Buyer's signature over the EIP-712 `Acceptance` digest: recovery byte (27 or 28).
    /// @param r Signature r.
    /// @param s Signature s, in the lower half of the curve order.
    struct LightContract {
        Offer offer;
        address buyer;
        int64 sellerX;
        int64 sellerY;
        uint8 v;
        bytes32 r;
        bytes32 s;
    }

    /// @notice The revealed path information, in the buyer's frame.
    /// @param x Purchased vector to the site, x, micro units (rotated offer plus seller position).
    /// @param y Same, y.
    /// @param direction Direction of the rotated offer (before adding the seller position), microdegrees.
    /// @param salt Seller's random nonce, so that the committed hash cannot be inverted by guessing.
    struct PathInfo {
        int64 x;
        int64 y;
        uint32 direction;
        bytes32 salt;
    }

    /// @notice One sale recorded under its buyer until the buyer's next deposit (one storage slot).
    /// @param seller Who sold it.
    /// @param site 0 = food, 1 = nest.
    /// @param direction Direction of the sold vector in the buyer's frame, microdegrees.
    struct Information {
        address seller;
        uint8 site;
        uint32 direction;
    }

    // ------------------------------------------------------------------------------------------------
    // Events (past tense, emitted right after the state change they report)
    // ------------------------------------------------------------------------------------------------

    /// @notice The market granted `amount` new tokens to `robot` (initial wealth).
    /// @param robot Receiving account.
    /// @param amount Tokens minted, 1e-9 units.
    event WealthGranted(address indexed robot, uint256 amount);

    /// @notice `seller` locked `amount` as stake for a sale to `buyer`; it joins the buyer's pot.
    /// @param seller Account whose balance paid the stake.
    /// @param buyer Account whose pot holds it until its next deposit.
    /// @param amount Stake, 1e-9 units.
    event StakeLocked(address indexed seller, address indexed buyer, uint256 amount);

    /// @notice A light contract was executed and its path information revealed.
    /// @param buyer Buyer of the information.
    /// @param seller Seller of the information.
    /// @param key `revealKey(site, age, maxBlock, buyer, seller)`, now spent.
    /// @param index Position of the record in the buyer's list of contributors.
    /// @param site 0 = food, 1 = nest.
    /// @param age Age of the information.
    /// @param x Revealed vector, x, micro units, buyer's frame.
    /// @param y Revealed vector, y.
    /// @param direction Direction of the rotated offer, microdegrees.
    event InformationRevealed(
        address indexed buyer,
        address indexed seller,
        bytes32 indexed key,
        uint256 index,
        uint8 site,
        uint32 age,
        int64 x,
        int64 y,
        uint32 direction
    );

    /// @notice The market paid `robot` the reward for one item and settled its round trip.
    /// @param robot Depositing robot.
    /// @param reward Reward minted to it, 1e-9 units.
    /// @param pot Stakes released to it before sharing.
    /// @param shared Amount actually paid to its sellers (the rest of the share is rounding dust it keeps).
    /// @param transactions Number of records settled.
    event ItemBought(address indexed robot, uint256 reward, uint256 pot, uint256 shared, uint256 transactions);

    /// @notice One record's seller received its share of a deposit.
    /// @param robot Depositing robot (the buyer of the information).
    /// @param seller Receiving seller.
    /// @param index Position of the record in the robot's list.
    /// @param weight The record's weight (1 under delayed payment, similar-transaction count otherwise).
    /// @param amount Share paid, 1e-9 units.
    event RewardShared(address indexed robot, address indexed seller, uint256 index, uint256 weight, uint256 amount);

    // ------------------------------------------------------------------------------------------------
    // Errors (EIP-6093 style: domain prefix and the values that explain the refusal)
    // ------------------------------------------------------------------------------------------------

    /// @notice `caller` is not the market account, the only one allowed to mint or buy items.
    /// @param caller Sender of the refused call.
    error InfoMarketUnauthorizedMarket(address caller);

    /// @notice `caller` submitted a light contract whose seller is `seller`; only the seller may reveal.
    /// @param caller Sender of the refused reveal.
    /// @param seller Seller named in the offer.
    error InfoMarketUnauthorizedSeller(address caller, address seller);

    /// @notice The reveal came after the agreed last block.
    /// @param maxBlock Last block the light contract allowed.
    /// @param currentBlock Block the reveal would have been included in.
    error InfoMarketExpiredContract(uint64 maxBlock, uint256 currentBlock);

    /// @notice The buyer's signature does not recover to the buyer named in the light contract.
    /// @param buyer Buyer named in the light contract.
    /// @param recovered Address the signature recovers to (zero when it recovers to none).
    error InfoMarketInvalidBuyerSignature(address buyer, address recovered);

    /// @notice The signature's s lies in the upper half of the curve order (a malleated copy).
    /// @param s The refused s value.
    error InfoMarketMalleableSignature(bytes32 s);

    /// @notice This (site, age, max block, buyer, seller) tuple was already revealed once.
    /// @param key The spent `revealKey`.
    error InfoMarketAlreadyRevealed(bytes32 key);

    /// @notice The revealed path information does not hash to the committed value.
    /// @param committed Hash in the light contract.
    /// @param revealed Hash of the revealed information.
    error InfoMarketInformationMismatch(bytes32 committed, bytes32 revealed);

    /// @notice The seller cannot lock the stake the market requires for a sale.
    /// @param robot The seller.
    /// @param balance Its free balance.
    /// @param needed The stake.
    error InfoMarketInsufficientStake(address robot, uint256 balance, uint256 needed);

    /// @notice A robot tried to sell to itself.
    /// @param robot Both buyer and seller.
    error InfoMarketSelfDealing(address robot);

    /// @notice The site code is neither food (0) nor nest (1).
    /// @param site The refused code.
    error InfoMarketInvalidSite(uint8 site);

    /// @notice The direction is not in [0, 360e6) microdegrees.
    /// @param direction The refused value.
    error InfoMarketInvalidDirection(uint32 direction);

    /// @notice The buyer already holds the most records one deposit can settle within a block's gas.
    /// @param buyer The buyer.
    /// @param limit `maxContributors()`.
    error InfoMarketTooManyContributors(address buyer, uint256 limit);

    /// @notice A constructor argument is out of range.
    /// @param parameter Name of the argument (ASCII, right-padded with zeros).
    /// @param value Its value.
    error InfoMarketInvalidParameter(bytes32 parameter, uint256 value);

    // ------------------------------------------------------------------------------------------------
    // Constants and configuration
    // ------------------------------------------------------------------------------------------------

    /// @dev One whole information share (the share is a WAD).
    uint256 private constant _WAD = 1e18;
    uint32 private constant _FULL_TURN = 360_000_000;
    uint32 private constant _HALF_TURN = 180_000_000;
    /// @dev secp256k1 order / 2: a larger s is the malleated twin of a valid signature (EIP-2).
    uint256 private constant _HALF_ORDER = 0x7fffffffffffffffffffffffffffffff5d576e7357a4501ddfe92f46681b20a0;

    bytes32 private constant _DOMAIN_TYPEHASH =
        keccak256("EIP712Domain(string name,string version,uint256 chainId,address verifyingContract)");
    bytes32 private constant _OFFER_TYPEHASH =
        keccak256("Offer(address seller,uint8 site,uint32 age,uint64 maxBlock,bytes32 pathHash)");
    bytes32 private constant _ACCEPTANCE_TYPEHASH = keccak256(
        "Acceptance(Offer offer,address buyer,int64 sellerX,int64 sellerY)"
        "Offer(address seller,uint8 site,uint32 age,uint64 maxBlock,bytes32 pathHash)"
    );
    bytes32 private constant _NAME_HASH = keccak256("InformationMarket");
    bytes32 private constant _VERSION_HASH = keccak256("1");

    address private immutable _market;
    Scheme private immutable _scheme;
    uint256 private immutable _reward;
    uint256 private immutable _informationShare;
    uint256 private immutable _stake;
    uint32 private immutable _theta;
    uint256 private immutable _maxContributors;
    uint256 private immutable _cachedChainId;
    bytes32 private immutable _cachedDomainSeparator;

    // ------------------------------------------------------------------------------------------------
    // State
    // ------------------------------------------------------------------------------------------------

    uint256 private _totalSupply;
    mapping(address robot => uint256) private _balances;
    /// @dev Stakes locked by the sales recorded under each buyer, released at its next deposit.
    mapping(address buyer => uint256) private _pots;
    /// @dev The buyer's records live in slots [0, count); clearing a list only resets its count, so the
    /// next round trip rewrites warm non-zero slots (about 5k gas) instead of fresh ones (about 22k).
    mapping(address buyer => mapping(uint256 => Information)) private _records;
    mapping(address buyer => uint256) private _recordCount;
    mapping(bytes32 key => bool) private _revealed;

    /// @notice Deploys a market with a fixed payment scheme; `market` alone can grant wealth and buy items.
    /// @param market_ Account of the market node.
    /// @param scheme_ Payment scheme.
    /// @param reward_ Reward R per item, 1e-9 units.
    /// @param informationShare_ Part of R shared with the sellers, as a WAD (0.5 = 5e17); at most 1e18.
    /// @param stake_ Stake per sale, 1e-9 units (0 = no staking); must be 0 under delayed payment.
    /// @param theta_ Similarity window, microdegrees, at most 180e6 (only the outlier scheme uses it).
    /// @param maxContributors_ Most records one buyer may hold; bounds `buyItem`'s gas (at least 1).
    constructor(
        address market_,
        Scheme scheme_,
        uint256 reward_,
        uint256 informationShare_,
        uint256 stake_,
        uint32 theta_,
        uint256 maxContributors_
    ) {
        if (market_ == address(0)) revert InfoMarketInvalidParameter("market", 0);
        if (informationShare_ > _WAD) revert InfoMarketInvalidParameter("informationShare", informationShare_);
        if (scheme_ == Scheme.Delayed && stake_ != 0) revert InfoMarketInvalidParameter("stake", stake_);
        if (theta_ > _HALF_TURN) revert InfoMarketInvalidParameter("theta", theta_);
        if (maxContributors_ == 0) revert InfoMarketInvalidParameter("maxContributors", 0);
        _market = market_;
        _scheme = scheme_;
        _reward = reward_;
        _informationShare = informationShare_;
        _stake = stake_;
        _theta = theta_;
        _maxContributors = maxContributors_;
        _cachedChainId = block.chainid;
        _cachedDomainSeparator = _buildDomainSeparator();
    }

    // ------------------------------------------------------------------------------------------------
    // Market functions
    // ------------------------------------------------------------------------------------------------

    /// @notice Mints `amount` tokens to `robot`: how robots receive their initial wealth.
    /// @dev Requirements: the caller is the market. Emits a {WealthGranted} event.
    /// @param robot Receiving account.
    /// @param amount Tokens, 1e-9 units.
    function grantWealth(address robot, uint256 amount) external {
        _requireMarket();
        _balances[robot] += amount;
        _totalSupply += amount;
        emit WealthGranted(robot, amount);
    }

    /// @notice Buys the item `robot` deposited: pays it the reward, then shares the information part of
    /// the reward (plus its pot of stakes under the outlier scheme) among the sellers of its records,
    /// and clears its records and pot.
    /// @dev Each record x receives floor(shared * w_x / sum w); the remainder stays with `robot`, so the
    /// supply changes by exactly the reward. With no records nothing is shared. Requirements: the caller
    /// is the market. Emits an {ItemBought} event and one {RewardShared} event per record.
    /// @param robot The depositing robot.
    function buyItem(address robot) external {
        _requireMarket();
        uint256 n = _recordCount[robot];
        uint256 pot = _pots[robot];
        // The pot is empty under delayed payment: the constructor refuses stakes with that scheme.
        uint256 amount = (_reward * _informationShare) / _WAD + pot;

        uint256 paid;
        if (n > 0) {
            mapping(uint256 => Information) storage records = _records[robot];
            address[] memory sellers = new address[](n);
            uint256[] memory keys = new uint256[](n);
            for (uint256 i; i < n; ++i) {
                Information storage record = records[i];
                sellers[i] = record.seller;
                keys[i] = (uint256(record.site) << 32) | record.direction;
            }
            uint256[] memory weights = _weights(keys);
            uint256 total;
            for (uint256 i; i < n; ++i) total += weights[i];
            for (uint256 i; i < n; ++i) {
                uint256 share = (amount * weights[i]) / total;
                _balances[sellers[i]] += share;
                paid += share;
                emit RewardShared(robot, sellers[i], i, weights[i], share);
            }
        }
        // The robot receives the reward and its pot, and pays what its sellers received: it never goes
        // negative because `paid <= informationShare * reward + pot <= reward + pot`.
        _balances[robot] = _balances[robot] + _reward + pot - paid;
        _totalSupply += _reward;
        _pots[robot] = 0;
        _recordCount[robot] = 0;
        emit ItemBought(robot, _reward, pot, paid, n);
    }

    // ------------------------------------------------------------------------------------------------
    // Seller function
    // ------------------------------------------------------------------------------------------------

    /// @notice Executes a light contract: records the sale under the buyer, reveals the path information
    /// and locks the seller's stake.
    /// @dev Checks, each with its own error: the seller is the caller; the current block is at most the
    /// agreed max block; the buyer's EIP-712 signature over the acceptance is valid and not malleable;
    /// (site, age, max block, buyer, seller) was never revealed before; the information hashes to the
    /// committed value; the seller can lock the stake; the buyer has room for another record.
    /// Emits {StakeLocked} (under staking) and {InformationRevealed}.
    /// @param lc The double-signed light contract.
    /// @param info The path information in the buyer's frame.
    function revealInformation(LightContract calldata lc, PathInfo calldata info) external {
        Offer calldata offer = lc.offer;
        address seller = offer.seller;
        address buyer = lc.buyer;
        if (msg.sender != seller) revert InfoMarketUnauthorizedSeller(msg.sender, seller);
        if (block.number > offer.maxBlock) revert InfoMarketExpiredContract(offer.maxBlock, block.number);
        if (buyer == seller) revert InfoMarketSelfDealing(seller);
        if (offer.site > 1) revert InfoMarketInvalidSite(offer.site);
        if (info.direction >= _FULL_TURN) revert InfoMarketInvalidDirection(info.direction);

        _checkBuyerSignature(lc);

        bytes32 key = revealKey(offer.site, offer.age, offer.maxBlock, buyer, seller);
        if (_revealed[key]) revert InfoMarketAlreadyRevealed(key);
        _revealed[key] = true;

        bytes32 revealed = keccak256(abi.encode(info.x, info.y, info.direction, info.salt));
        if (revealed != offer.pathHash) revert InfoMarketInformationMismatch(offer.pathHash, revealed);

        uint256 index = _recordCount[buyer];
        if (index >= _maxContributors) revert InfoMarketTooManyContributors(buyer, _maxContributors);

        uint256 stake_ = _stake;
        if (stake_ > 0) {
            uint256 balance = _balances[seller];
            if (balance < stake_) revert InfoMarketInsufficientStake(seller, balance, stake_);
            _balances[seller] = balance - stake_;
            _pots[buyer] += stake_;
            emit StakeLocked(seller, buyer, stake_);
        }

        _records[buyer][index] = Information(seller, offer.site, info.direction);
        _recordCount[buyer] = index + 1;
        emit InformationRevealed(buyer, seller, key, index, offer.site, offer.age, info.x, info.y, info.direction);
    }

    // ------------------------------------------------------------------------------------------------
    // Views
    // ------------------------------------------------------------------------------------------------

    /// @notice Free (unlocked) balance of `robot`, 1e-9 units.
    /// @param robot The account.
    /// @return The balance.
    function balanceOf(address robot) external view returns (uint256) {
        return _balances[robot];
    }

    /// @notice Stakes locked by the sales recorded under `buyer`, released at its next deposit.
    /// @param buyer The account.
    /// @return The pot, 1e-9 units.
    function lockedStake(address buyer) external view returns (uint256) {
        return _pots[buyer];
    }

    /// @notice Tokens in existence: all balances plus all pots.
    /// @return The supply, 1e-9 units.
    function totalSupply() external view returns (uint256) {
        return _totalSupply;
    }

    /// @notice Decimals of the token amounts (1 token = 1e9 units).
    /// @return Always 9.
    function decimals() external pure returns (uint8) {
        return 9;
    }

    /// @notice The records `buyer` accumulated since its last deposit, in reveal order.
    /// @param buyer The account.
    /// @return list Its contributors' records.
    function contributors(address buyer) external view returns (Information[] memory list) {
        uint256 n = _recordCount[buyer];
        list = new Information[](n);
        for (uint256 i; i < n; ++i) list[i] = _records[buyer][i];
    }

    /// @notice Whether the light contract identified by `key` was already revealed.
    /// @param key A `revealKey`.
    /// @return True once revealed.
    function isRevealed(bytes32 key) external view returns (bool) {
        return _revealed[key];
    }

    /// @notice The identity of a light contract for the never-twice check: the paper's tuple.
    /// @param site Site code.
    /// @param age Information age.
    /// @param maxBlock Agreed last block.
    /// @param buyer Buyer.
    /// @param seller Seller.
    /// @return `keccak256(abi.encode(site, age, maxBlock, buyer, seller))`.
    function revealKey(uint8 site, uint32 age, uint64 maxBlock, address buyer, address seller)
        public
        pure
        returns (bytes32)
    {
        return keccak256(abi.encode(site, age, maxBlock, buyer, seller));
    }

    /// @notice The EIP-712 digest the buyer signs to accept `offer` (for clients to cross-check).
    /// @param offer The offer.
    /// @param buyer The buyer.
    /// @param sellerX Seller's position in the buyer's frame, x.
    /// @param sellerY Same, y.
    /// @return The digest.
    function acceptanceDigest(Offer calldata offer, address buyer, int64 sellerX, int64 sellerY)
        public
        view
        returns (bytes32)
    {
        bytes32 offerHash = keccak256(
            abi.encode(_OFFER_TYPEHASH, offer.seller, offer.site, offer.age, offer.maxBlock, offer.pathHash)
        );
        bytes32 structHash = keccak256(abi.encode(_ACCEPTANCE_TYPEHASH, offerHash, buyer, sellerX, sellerY));
        return keccak256(abi.encodePacked(hex"1901", _domainSeparator(), structHash));
    }

    /// @notice The EIP-712 domain (EIP-5267), so that clients sign for this contract on this chain only.
    /// @return fields Bit mask of the fields used (name, version, chainId, verifyingContract).
    /// @return name "InformationMarket".
    /// @return version "1".
    /// @return chainId Current chain id.
    /// @return verifyingContract This contract.
    /// @return salt Unused.
    /// @return extensions None.
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
        return (hex"0f", "InformationMarket", "1", block.chainid, address(this), bytes32(0), new uint256[](0));
    }

    /// @notice The market's configuration.
    /// @return market_ Market account.
    /// @return scheme_ Payment scheme.
    /// @return reward_ Reward per item, 1e-9 units.
    /// @return informationShare_ Shared part of the reward, WAD.
    /// @return stake_ Stake per sale, 1e-9 units.
    /// @return theta_ Similarity window, microdegrees.
    /// @return maxContributors_ Most records per buyer.
    function configuration()
        external
        view
        returns (
            address market_,
            Scheme scheme_,
            uint256 reward_,
            uint256 informationShare_,
            uint256 stake_,
            uint32 theta_,
            uint256 maxContributors_
        )
    {
        return (_market, _scheme, _reward, _informationShare, _stake, _theta, _maxContributors);
    }

    // ------------------------------------------------------------------------------------------------
    // Internal
    // ------------------------------------------------------------------------------------------------

    function _requireMarket() private view {
        if (msg.sender != _market) revert InfoMarketUnauthorizedMarket(msg.sender);
    }

    function _checkBuyerSignature(LightContract calldata lc) private view {
        if (uint256(lc.s) > _HALF_ORDER) revert InfoMarketMalleableSignature(lc.s);
        bytes32 digest = acceptanceDigest(lc.offer, lc.buyer, lc.sellerX, lc.sellerY);
        address recovered = ecrecover(digest, lc.v, lc.r, lc.s);
        if (recovered == address(0) || recovered != lc.buyer) revert InfoMarketInvalidBuyerSignature(lc.buyer, recovered);
    }

    /// @dev Weights of a round trip's records, given as `site << 32 | direction`. Delayed: 1 each.
    /// Outlier: for each record, the number of same-site records (itself included) whose direction is
    /// circularly within theta of its own. Each pair is compared once and credited to both, so the cost
    /// is n(n-1)/2 comparisons; within one site the keys differ only in their direction bits, so the
    /// key difference is the direction difference.
    function _weights(uint256[] memory keys) private view returns (uint256[] memory weights) {
        uint256 n = keys.length;
        weights = new uint256[](n);
        if (_scheme == Scheme.Delayed) {
            for (uint256 i; i < n; ++i) weights[i] = 1;
            return weights;
        }
        uint256 theta = _theta;
        unchecked {
            for (uint256 i; i < n; ++i) {
                uint256 a = keys[i];
                uint256 similar = weights[i] + 1;
                for (uint256 j = i + 1; j < n; ++j) {
                    uint256 b = keys[j];
                    if ((a ^ b) >> 32 != 0) continue;
                    uint256 d = a > b ? a - b : b - a;
                    if (d > _HALF_TURN) d = _FULL_TURN - d;
                    if (d < theta) {
                        ++similar;
                        ++weights[j];
                    }
                }
                weights[i] = similar;
            }
        }
    }

    function _domainSeparator() private view returns (bytes32) {
        return block.chainid == _cachedChainId ? _cachedDomainSeparator : _buildDomainSeparator();
    }

    function _buildDomainSeparator() private view returns (bytes32) {
        return keccak256(abi.encode(_DOMAIN_TYPEHASH, _NAME_HASH, _VERSION_HASH, block.chainid, address(this)));
    }
}
