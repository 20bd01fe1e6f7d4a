// SPDX-License-Identifier: MIT
pragma solidity 0.8.28;

import {IInformationMarket} from "../IInformationMarket.sol";

/// @title MarketStorage
/// @notice The market's constants, its configuration (immutables, checked once by the constructor) and
/// its whole state: the ground every module of {InformationMarket} stands on.
/// @dev Every state variable of the market is declared here, in the order of the deployed storage layout
/// (slot 0 `_totalSupply` to slot 17 `_exits`): the modules share one layout fixed in one file, so that
/// composing them in another order can never move a slot. The modules own the variables they write:
/// {MarketRoles} `_roles`, `_roleGrants` and `_paused`; {MarketRegistration} `_registered`,
/// `_approvers`, `_approvedAt`, `_quotaUsed`, `_quotaBlocks` and `_exits`; {LightContracts} `_records`,
/// `_rounds`, `_sold`, `_repeats`, `_revealed` and, with {MarketSettlement}, `_pots` and `_balances`;
/// {MarketSettlement} `_settlements` and `_totalSupply` (also minted and burned by registration).
abstract contract MarketStorage is IInformationMarket {
    /// @dev One whole information share (the share is a WAD).
    uint256 internal constant _WAD = 1e18;
    /// @dev Scale of cos(theta): 1e9 = 1. With components below 2^47, every product of the similarity
    /// test stays below 2^250.
    int256 internal constant _COS_SCALE = 1e9;
    int256 internal constant _MAX_COMPONENT = 2 ** 47;
    /// @dev Pair comparisons that count as one unit of settlement work: a distinct-seller comparison
    /// costs more (it looks up the other record's seller), so fewer of them make a unit.
    uint256 internal constant _PAIRS_PER_UNIT = 64;
    uint256 internal constant _DISTINCT_PAIRS_PER_UNIT = 40;
    /// @dev Most live records a round trip may ever hold, and most work units one call may do: the
    /// bounds the declared gas per transaction is measured at (docs/gas.md).
    uint256 internal constant _MAX_TRIP_RECORDS = 512;
    uint256 internal constant _MAX_SETTLE_BATCH = 48;
    /// @dev Most units of work one settlement can take, with one to spare: a weighing (at most
    /// ceil(512 / 40) = 13 units) and a payment per record. The bounty of them all fits in the share.
    uint256 internal constant _MAX_SETTLEMENT_UNITS = _MAX_TRIP_RECORDS * 15;
    /// @dev Scale of an OutlierDistinct weight (distinct sellers / seller's records, as a fixed point).
    uint256 internal constant _DISTINCT_SCALE = 1e27;
    /// @dev The site code a void OutlierCapped record takes while weighing: no record is of it, so no
    /// comparison counts it.
    uint256 internal constant _VOID = 2;
    /// @dev Under OutlierCapped the reward and the stake stay below this, so that no product of the
    /// payment (amount * (share + 512 stakes) * 512) can overflow.
    uint256 internal constant _MAX_CAPPED_AMOUNT = 2 ** 96;
    /// @dev Longest bond delay, blocks: block numbers plus it never overflow 64 bits.
    uint64 internal constant _MAX_DELAY = 2 ** 40;
    /// @dev Settlement phases: closed (nothing done yet), weighing, paying.
    uint8 internal constant _CLOSED_TRIP = 0;
    uint8 internal constant _WEIGH = 1;
    uint8 internal constant _PAY = 2;
    /// @dev An identity's life after registration: active (`_registered`), exiting (bond locked until
    /// `_exits[robot].at`), closed (bond returned; the robot may not register again), revoked (bond
    /// burned; reinstated by more registrars than revoked it before `_exits[robot].at`, else for good).
    uint8 internal constant _EXITING = 1;
    uint8 internal constant _CLOSED = 2;
    uint8 internal constant _REVOKED = 3;
    /// @dev An approval withdrawn by its registrar.
    uint256 internal constant _CANCELLED = type(uint256).max;

    /// @dev A buyer's records are `_records[buyer][i]`; its open round trip is [start, count) and began
    /// at index `first` (the two are equal: a round trip is closed whole). `trip` numbers its round trips.
    struct Round {
        uint64 start;
        uint64 count;
        uint64 trip;
        uint64 first;
    }

    /// @dev A deposited round trip being settled, records [next, end) still to process in `phase`
    /// (in the weighing phase `next` is the next record to weigh).
    /// `escrow` holds the reward share and the stakes not yet paid out; `amount` is what the records
    /// share (fixed when paying starts); `first` is the round trip's first record and `live` the first
    /// one weighed (the same record: every record of a round trip is weighed and paid by weight).
    /// `counted`: under OutlierCapped, how many of the live records weighed so far count (are not void).
    struct Settlement {
        uint64 next;
        uint64 end;
        uint64 closedAt;
        uint64 live;
        uint8 phase;
        uint64 first;
        uint64 counted;
        uint256 escrow;
        uint256 amount;
        uint256 totalWeight;
    }

    Scheme internal immutable _scheme;
    uint256 internal immutable _reward;
    uint256 internal immutable _informationShare;
    uint256 internal immutable _stake;
    int256 internal immutable _cosTheta;
    uint64 internal immutable _stakeExpiry;
    uint256 internal immutable _maxRecordsPerSeller;
    uint256 internal immutable _maxRecordsPerTrip;
    uint64 internal immutable _maxValidity;
    uint256 internal immutable _settleBatch;
    uint64 internal immutable _settlementDeadline;
    uint256 internal immutable _maxGrant;
    uint256 internal immutable _settleBounty;
    uint256 internal immutable _registrarThreshold;
    uint256 internal immutable _registrarQuota;
    uint64 internal immutable _registrarPeriod;
    uint256 internal immutable _registrationBond;
    uint64 internal immutable _bondDelay;
    uint256 internal immutable _cap;

    uint256 internal _totalSupply;
    mapping(address robot => uint256) internal _balances;
    /// @dev Stakes locked by the records of each buyer's open round trip.
    mapping(address buyer => uint256) internal _pots;
    mapping(address buyer => mapping(uint256 => Information)) internal _records;
    mapping(address buyer => Round) internal _rounds;
    mapping(address buyer => Settlement) internal _settlements;
    /// @dev ((round trip + 1) << 128) | (index of the seller's last record << 64) | records sold in
    /// the round trip, per buyer and seller (0: none yet).
    mapping(address buyer => mapping(address seller => uint256)) internal _sold;
    /// @dev ((round trip + 1) << 64) | records of the round trip that were not their seller's first in it,
    /// per buyer (0: none yet).
    mapping(address buyer => uint256) internal _repeats;
    mapping(bytes32 key => bool) internal _revealed;
    mapping(address robot => bool) internal _registered;
    mapping(bytes32 role => mapping(address account => bool)) internal _roles;
    /// @dev Per request (keccak256(robot, amount), or keccak256("revoke", robot)): every registrar key that
    /// ever approved it, and the block of each one's approval (`_CANCELLED` once withdrawn). An approval
    /// stands while its key holds the registrar role, held it when approving, and for `registrarPeriod`
    /// blocks.
    mapping(bytes32 request => address[]) internal _approvers;
    /// (The approval is packed: (the key's registrar grants when it approved << 64) | block.)
    mapping(bytes32 request => mapping(address registrar => uint256)) internal _approvedAt;
    /// @dev How many times an account was granted a role: an approval given under an earlier grant does
    /// not stand.
    mapping(bytes32 role => mapping(address account => uint256)) internal _roleGrants;
    /// @dev Approvals (and revocation approvals) each registrar made, and the blocks of its last
    /// `registrarQuota` ones, a ring: a new one is allowed when the one `registrarQuota` back is
    /// `registrarPeriod` blocks old, so no window of that many blocks holds more than the quota.
    mapping(address registrar => uint256) internal _quotaUsed;
    mapping(address registrar => mapping(uint256 slot => uint64)) internal _quotaBlocks;
    bool internal _paused;
    /// @dev Exits: the block from which the bond may be withdrawn (exiting) or until which a revocation
    /// may be reversed (revoked), the identity's state, how many times it was reinstated (revocation
    /// and reinstatement approvals are counted per reinstatement) and whether it was exiting when revoked.
    struct Exit {
        uint64 at;
        uint8 state;
        uint64 reinstated;
        bool exiting;
    }
    mapping(address robot => Exit) internal _exits;

    /// @dev Checks every parameter (documented on {InformationMarket}'s constructor), in the order that
    /// decides which error a deployment with several wrong ones gets, and keeps the configuration.
    constructor(
        address market_,
        Scheme scheme_,
        uint256 reward_,
        uint256 informationShare_,
        uint256 stake_,
        int256 cosTheta_,
        uint64 stakeExpiry_,
        uint256 maxRecordsPerSeller_,
        uint256 maxRecordsPerTrip_,
        uint64 maxValidity_,
        uint256 settleBatch_,
        uint64 settlementDeadline_,
        uint256 maxGrant_,
        address[] memory registrars_,
        uint256 registrarThreshold_,
        uint256 registrarQuota_,
        uint64 registrarPeriod_,
        address nest_,
        uint256 settleBounty_,
        uint256 registrationBond_,
        uint64 bondDelay_,
        uint256 cap_
    ) {
        if (market_ == address(0)) revert InfoMarketInvalidParameter("market", 0);
        if (nest_ == address(0)) revert InfoMarketInvalidParameter("nest", 0);
        if (registrarThreshold_ == 0 || registrarThreshold_ > registrars_.length) {
            revert InfoMarketInvalidParameter("registrarThreshold", int256(registrarThreshold_));
        }
        if (registrarQuota_ == 0) revert InfoMarketInvalidParameter("registrarQuota", 0);
        if (registrarPeriod_ == 0) revert InfoMarketInvalidParameter("registrarPeriod", 0);
        if (settleBounty_ * _MAX_SETTLEMENT_UNITS > (reward_ * informationShare_) / _WAD) {
            revert InfoMarketInvalidParameter("settleBounty", int256(settleBounty_));
        }
        if (informationShare_ > _WAD) revert InfoMarketInvalidParameter("informationShare", int256(informationShare_));
        if (scheme_ == Scheme.Delayed && stake_ != 0) revert InfoMarketInvalidParameter("stake", int256(stake_));
        if (cosTheta_ > _COS_SCALE || cosTheta_ < -_COS_SCALE) revert InfoMarketInvalidParameter("cosTheta", cosTheta_);
        if (maxRecordsPerSeller_ == 0 || maxRecordsPerSeller_ >= 2 ** 32) {
            revert InfoMarketInvalidParameter("maxRecordsPerSeller", int256(maxRecordsPerSeller_));
        }
        if (maxRecordsPerTrip_ == 0 || maxRecordsPerTrip_ > _MAX_TRIP_RECORDS) {
            revert InfoMarketInvalidParameter("maxRecordsPerTrip", int256(maxRecordsPerTrip_));
        }
        if (stakeExpiry_ == 0) revert InfoMarketInvalidParameter("stakeExpiry", 0);
        if (maxValidity_ == 0) revert InfoMarketInvalidParameter("maxValidity", 0);
        if (settleBatch_ == 0 || settleBatch_ > _MAX_SETTLE_BATCH) {
            revert InfoMarketInvalidParameter("settleBatch", int256(settleBatch_));
        }
        if (settlementDeadline_ == 0) revert InfoMarketInvalidParameter("settlementDeadline", 0);
        if (registrationBond_ > maxGrant_) {
            revert InfoMarketInvalidParameter("registrationBond", int256(registrationBond_));
        }
        // Beyond 2^40 blocks (about 400 000 years) `exit` would overflow the block it computes.
        if (bondDelay_ == 0 || bondDelay_ > _MAX_DELAY) {
            revert InfoMarketInvalidParameter("bondDelay", int256(uint256(bondDelay_)));
        }
        if (scheme_ == Scheme.OutlierCapped ? cap_ == 0 : cap_ != 0) revert InfoMarketInvalidParameter("cap", int256(cap_));
        if (scheme_ == Scheme.OutlierCapped) {
            if (reward_ >= _MAX_CAPPED_AMOUNT) revert InfoMarketInvalidParameter("reward", int256(reward_));
            if (stake_ >= _MAX_CAPPED_AMOUNT) revert InfoMarketInvalidParameter("stake", int256(stake_));
        }
        _cap = cap_;
        _registrationBond = registrationBond_;
        _bondDelay = bondDelay_;
        _registrarThreshold = registrarThreshold_;
        _registrarQuota = registrarQuota_;
        _registrarPeriod = registrarPeriod_;
        _settleBounty = settleBounty_;
        _scheme = scheme_;
        _reward = reward_;
        _informationShare = informationShare_;
        _stake = stake_;
        _cosTheta = cosTheta_;
        _stakeExpiry = stakeExpiry_;
        _maxRecordsPerSeller = maxRecordsPerSeller_;
        _maxRecordsPerTrip = maxRecordsPerTrip_;
        _maxValidity = maxValidity_;
        _settleBatch = settleBatch_;
        _settlementDeadline = settlementDeadline_;
        _maxGrant = maxGrant_;
    }

    /// @inheritdoc IInformationMarket
    function configuration()
        external
        view
        returns (
            Scheme scheme_,
            uint256 reward_,
            uint256 informationShare_,
            uint256 stake_,
            int256 cosTheta_,
            uint64 stakeExpiry_,
            uint256 maxRecordsPerSeller_,
            uint256 maxRecordsPerTrip_,
            uint64 maxValidity_,
            uint256 settleBatch_,
            uint64 settlementDeadline_,
            uint256 maxGrant_,
            uint256 settleBounty_,
            uint256 cap_
        )
    {
        return (
            _scheme,
            _reward,
            _informationShare,
            _stake,
            _cosTheta,
            _stakeExpiry,
            _maxRecordsPerSeller,
            _maxRecordsPerTrip,
            _maxValidity,
            _settleBatch,
            _settlementDeadline,
            _maxGrant,
            _settleBounty,
            _cap
        );
    }

    /// @inheritdoc IInformationMarket
    function policy()
        external
        view
        returns (uint256 threshold, uint256 quota, uint64 period, uint256 bond, uint64 bondDelay)
    {
        return (_registrarThreshold, _registrarQuota, _registrarPeriod, _registrationBond, _bondDelay);
    }
}
