// SPDX-License-Identifier: MIT
pragma solidity 0.8.28;

/// @title InformationMarket
/// @notice On-chain half of the robot swarm's information market (docs/model.md §5 and §9): sellers
/// reveal path information under a light contract the buyer signed off-chain, and the market account
/// pays every deposited item and shares part of the reward among the robot's information sellers.
/// @dev Balances live in an internal ledger of this contract's own token (9 decimals), not in an
/// ERC-20: robots never transfer tokens to each other directly, every movement of money is one of the
/// market's rules (stake, reward, share), and leaving `transfer`/`approve` out keeps the only ways to
/// move money the ones this contract audits. Invariant: the sum of all balances plus all locked stakes
/// and bonds equals `totalSupply()` (initial wealth granted plus every reward issued, less the bonds
/// forfeited); stakes still locked in a buyer's pot or in a settlement count as locked. Rounding dust of a share stays with the depositing
/// robot, so no token is ever created or destroyed by a division.
///
/// The contract trusts no seller's word about its information: the direction each record is weighed
/// by is that of the vector the seller committed to, minus the seller's position the buyer signed
/// (docs/model.md §4), and "within theta" is decided on those integer vectors with dot products
/// against a fixed cos(theta), exactly. A stake never stays locked for ever: once the first record of a
/// round trip is `stakeExpiry` blocks old (never 0), anyone may settle the whole round trip
/// (`refundExpired`) as a prompt deposit would, every record weighed, the share paid out of the buyer's
/// balance as far as it goes (it gets the whole reward at its next deposit), so neither the buyer nor a
/// seller of many records gains anything by letting records expire; a deposit not weighed within
/// `settlementDeadline` blocks is still weighed, never paid by a cruder rule (so nobody gains by
/// leaving it unfinished), and from then on any caller earns the bounty for finishing it. Every call
/// does a bounded amount of work: a round trip holds at most
/// `maxRecordsPerTrip` (<= 512) live records, one seller at most `maxRecordsPerSeller` of them, and
/// `buyItem`, `settle` and `refundExpired` each do at most `settleBatch` (<= 48) units of work, so no
/// call exceeds the gas bound docs/gas.md declares, measured with cold storage, whatever the number of
/// records or sellers. A registered robot that settles someone's deposit earns `settleBounty` per unit
/// of work, taken from the share, so settling is worth doing for whoever does it.
///
/// Trust (docs/chain.md, "Trust model"): roles, as in OpenZeppelin's AccessControl. The admin grants
/// and revokes roles (key rotation; several accounts may hold a role). A robot is registered when
/// `registrarThreshold` distinct registrars approved the same (robot, grant), each approval standing
/// only while its key holds the registrar role and for `registrarPeriod` blocks (its registrar may
/// cancel it), and a registrar approves (registrations and revocations together) at most
/// `registrarQuota` times in any `registrarPeriod` consecutive blocks. Registering locks `registrationBond` of
/// the robot's grant as its bond: it comes back to the robot `bondDelay` blocks after the robot leaves
/// the market (`exit`, then `withdrawBond`), and is forfeited (burned) when `registrarThreshold`
/// registrars revoke the robot (`revokeRegistration`), before or during that delay; `registrarThreshold`
/// + 1 registrars may reverse a revocation within `bondDelay` blocks (`reinstate`), minting the bond back. A depositor
/// submits a deposit only with its evidence: the robot's signature over its round trip and a nest's
/// acknowledgement of it. A
/// pauser stops registrations, reveals and deposits; settlements and expiries go on while paused, so no
/// stake is ever held by a pause. Only registered robots may buy, sell or be paid a reward (a record
/// revealed before its seller was revoked is still weighed and paid). A light
/// contract names the buyer's round trip it belongs to, so a reveal after the buyer's deposit is
/// refused rather than paid from the next item.
///
/// Fixed point: token amounts in units of 1e-9 token; positions and vectors in micro arena units
/// (signed); cos(theta) in units of 1e-9.
contract InformationMarket {
    // ------------------------------------------------------------------------------------------------
    // Types
    // ------------------------------------------------------------------------------------------------

    /// @notice How a deposit's reward share is split among the robot's sellers (docs/model.md §5).
    /// @dev Delayed: in proportion to each seller's number of transactions; no stakes allowed.
    /// Outlier: in proportion to the number of same-site transactions within theta of each transaction,
    /// with the locked stakes added to the shared amount (staking is on when `stake() > 0`).
    /// OutlierDistinct: like Outlier, but a transaction weighs the number of distinct sellers with a
    /// same-site transaction within theta (its own seller once), divided by its seller's number of
    /// transactions for that site in the round trip: one seller, one voice (docs/chain.md).
    /// OutlierCapped: at most `cap` records per seller count in a round trip (its first live ones); a
    /// later one is void: paid its stake back (scaled as the live records' amount is, when some records
    /// expired), it earns nothing and counts in nobody's weight. The counted records are weighed as under
    /// Outlier among themselves and share the rest (docs/defences.md, `capped_outlier`).
    enum Scheme {
        Delayed,
        Outlier,
        OutlierDistinct,
        OutlierCapped
    }

    /// @notice The seller's offer, which the buyer accepts without seeing the information itself.
    /// @param seller Account that sells and must submit the reveal.
    /// @param site 0 = food, 1 = nest.
    /// @param age Age of the offered information, in simulation steps.
    /// @param maxBlock Last block in which the reveal may be included (at most `maxValidity` ahead).
    /// @param pathHash `keccak256(abi.encode(x, y, salt))` of the `PathInfo` to be revealed.
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
    /// @param trip The buyer's round trip the sale belongs to (`roundTrip(buyer)` when signed).
    /// @param v Buyer's signature over the EIP-712 `Acceptance` digest: recovery byte (27 or 28).
    /// @param r Signature r.
    /// @param s Signature s, in the lower half of the curve order.
    struct LightContract {
        Offer offer;
        address buyer;
        int64 sellerX;
        int64 sellerY;
        uint64 trip;
        uint8 v;
        bytes32 r;
        bytes32 s;
    }

    /// @notice The revealed path information, in the buyer's frame. There is no declared direction:
    /// the contract derives it from the vector.
    /// @param x Purchased vector to the site, x, micro units (rotated offer plus seller position).
    /// @param y Same, y.
    /// @param salt Seller's random nonce, so that the committed hash cannot be inverted by guessing.
    struct PathInfo {
        int64 x;
        int64 y;
        bytes32 salt;
    }

    /// @notice One sale recorded under its buyer until the buyer's deposit settles it (two slots; the
    /// second holds all that weighing reads).
    /// @param seller Who sold it.
    /// @param openedAt Block of the reveal (its expiry counts from there).
    /// @param site 0 = food, 1 = nest.
    /// @param dx The seller's rotated vector in the buyer's frame (purchased vector minus the seller's
    /// position), x, micro units; a zero vector is stored as (1, 0), direction 0 like atan2(0, 0).
    /// @param dy Same, y.
    /// @param weight The record's weight, written while its round trip is settled (under
    /// OutlierDistinct scaled by 1e27: distinct sellers * 1e27 / the seller's records for the site; under
    /// OutlierCapped the count of similar counted records, 0 for a void record).
    /// @param prevGap How many records back the same seller's previous record of this round trip lies
    /// (0: none within reach).
    struct Information {
        address seller;
        uint64 openedAt;
        uint8 site;
        int64 dx;
        int64 dy;
        uint104 weight;
        uint16 prevGap;
    }

    /// @dev A buyer's records are `_records[buyer][i]`; its open round trip is [start, count) and began
    /// at index `first` (the two are equal: a round trip is closed whole). `trip` numbers its round trips.
    struct Round {
        uint64 start;
        uint64 count;
        uint64 trip;
        uint64 first;
    }

    /// @notice What a deposit carries: the robot's signature over `Deposit(robot, trip)` (it ends that
    /// round trip) and a nest's signature over the same message (it received the item).
    struct DepositEvidence {
        uint8 robotV;
        bytes32 robotR;
        bytes32 robotS;
        uint8 nestV;
        bytes32 nestR;
        bytes32 nestS;
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

    /// @notice A light contract was executed and its path information revealed. The event carries all
    /// a record's weight depends on, so a settlement can be recomputed from the logs alone.
    /// @param buyer Buyer of the information.
    /// @param seller Seller of the information.
    /// @param key `revealKey(site, age, maxBlock, buyer, seller, pathHash)`, now spent.
    /// @param index Position of the record in the buyer's list (`_records[buyer][index]`).
    /// @param site 0 = food, 1 = nest.
    /// @param age Age of the information.
    /// @param x Revealed vector, x, micro units, buyer's frame.
    /// @param y Revealed vector, y.
    /// @param sellerX Seller's position in the buyer's frame (signed by the buyer), x.
    /// @param sellerY Same, y.
    /// @param pathHash The commitment the revealed information matched.
    event InformationRevealed(
        address indexed buyer,
        address indexed seller,
        bytes32 indexed key,
        uint256 index,
        uint8 site,
        uint32 age,
        int64 x,
        int64 y,
        int64 sellerX,
        int64 sellerY,
        bytes32 pathHash
    );

    /// @notice `buyer`'s open round trip expired (its first record is `stakeExpiry` blocks old, or the
    /// buyer is no longer registered) and was closed for settlement as a deposit closes it: its records
    /// are weighed and paid ({RewardShared}) from its stakes and `share`, which the buyer paid from its
    /// balance (the reward's share, or the whole balance when that is less).
    /// @param buyer The buyer.
    /// @param share Paid by the buyer into the settlement, 1e-9 units.
    /// @param pot Stakes of the round trip.
    /// @param transactions Number of records in the round trip.
    event RoundTripExpired(address indexed buyer, uint256 share, uint256 pot, uint256 transactions);

    /// @notice The market paid `robot` the reward for one item and closed its round trip for settlement.
    /// @param robot Depositing robot.
    /// @param reward Reward minted to it, 1e-9 units.
    /// @param pot Stakes of the round trip.
    /// @param transactions Number of records in the round trip (each is weighed and paid).
    event ItemBought(address indexed robot, uint256 reward, uint256 pot, uint256 transactions);

    /// @notice One record's seller received its share of a deposit.
    /// @param robot Depositing robot (the buyer of the information).
    /// @param seller Receiving seller.
    /// @param index The record.
    /// @param weight The record's weight (1 under delayed payment, similar-transaction count under
    /// outlier, distinct-seller count * 1e27 / the seller's records for the site under outlier-distinct;
    /// under outlier-capped stake * C for a void record and (share + counted records * stake) * its count
    /// for a counted one, C the counts' sum).
    /// @param amount Share paid, 1e-9 units.
    event RewardShared(address indexed robot, address indexed seller, uint256 index, uint256 weight, uint256 amount);

    /// @notice `caller` earned `amount` for settling `robot`'s deposit (`settleBounty` per unit of work).
    /// @param caller The registered robot that called `settle`.
    /// @param robot The depositing robot.
    /// @param amount Bounty paid, 1e-9 units.
    event SettlementBountyPaid(address indexed caller, address indexed robot, uint256 amount);

    /// @notice `registrar` approved registering `robot` with initial wealth `amount`.
    /// @param registrar The approving registrar.
    /// @param robot The robot.
    /// @param amount The grant approved, 1e-9 units.
    /// @param approvals Distinct registrars that approved this (robot, amount) so far.
    event RegistrationApproved(address indexed registrar, address indexed robot, uint256 amount, uint256 approvals);

    /// @notice `robot`'s registration locked `amount` of its grant as its bond.
    /// @param robot The robot.
    /// @param amount The bond, 1e-9 units.
    event BondLocked(address indexed robot, uint256 amount);

    /// @notice `robot` left the market; its bond may be withdrawn from block `unlockBlock` on.
    /// @param robot The robot.
    /// @param unlockBlock First block of `withdrawBond`.
    event ExitRequested(address indexed robot, uint256 unlockBlock);

    /// @notice `robot`'s bond went back to its balance after a clean exit.
    /// @param robot The robot.
    /// @param amount The bond, 1e-9 units.
    event BondReturned(address indexed robot, uint256 amount);

    /// @notice `registrar` approved revoking `robot`.
    /// @param registrar The approving registrar.
    /// @param robot The robot.
    /// @param approvals Distinct registrars that approved revoking it so far.
    event RevocationApproved(address indexed registrar, address indexed robot, uint256 approvals);

    /// @notice `registrar` withdrew its approval of `request` (a registration or a revocation of `robot`).
    /// @param registrar The registrar.
    /// @param robot The robot.
    /// @param request keccak256(abi.encode(robot, amount)) or keccak256(abi.encode("revoke", robot)).
    event ApprovalCancelled(address indexed registrar, address indexed robot, bytes32 request);

    /// @notice `robot` was revoked and its bond burned.
    /// @param robot The robot.
    /// @param amount The bond, 1e-9 units.
    event BondForfeited(address indexed robot, uint256 amount);

    /// @notice `registrar` approved reversing `robot`'s revocation.
    /// @param registrar The approving registrar.
    /// @param robot The robot.
    /// @param approvals Distinct registrars that approved reinstating it so far.
    event ReinstatementApproved(address indexed registrar, address indexed robot, uint256 approvals);

    /// @notice `robot`'s revocation was reversed: it is registered again (or exiting again, when it was),
    /// with its bond restored.
    /// @param robot The robot.
    /// @param bond The bond restored (minted again), 1e-9 units.
    event RegistrationReinstated(address indexed robot, uint256 bond);

    /// @notice `account` received `role` from `sender`.
    /// @param role The role.
    /// @param account The account.
    /// @param sender The admin that granted it.
    event RoleGranted(bytes32 indexed role, address indexed account, address indexed sender);

    /// @notice `account` lost `role` (revoked by an admin, or renounced by `account` itself).
    /// @param role The role.
    /// @param account The account.
    /// @param sender Who revoked it.
    event RoleRevoked(bytes32 indexed role, address indexed account, address indexed sender);

    /// @notice Registrations, reveals and deposits stopped (`paused` true) or resumed.
    /// @param account The pauser.
    /// @param paused The new state.
    event PauseSet(address indexed account, bool paused);

    /// @notice A round trip's settlement finished: `shared` went to the sellers of its live records and
    /// `kept` (rounding dust, or the whole share when the round trip had no record) back to `robot`.
    /// @param robot Depositing robot.
    /// @param shared Sum of the shares paid.
    /// @param kept Returned to the robot.
    /// @param totalWeight Sum of the live records' weights (under OutlierCapped, of their counts: C).
    event SettlementCompleted(address indexed robot, uint256 shared, uint256 kept, uint256 totalWeight);

    // ------------------------------------------------------------------------------------------------
    // Errors (EIP-6093 style: domain prefix and the values that explain the refusal)
    // ------------------------------------------------------------------------------------------------

    /// @notice `caller` lacks `role`, which the call needs.
    /// @param caller Sender of the refused call.
    /// @param role The role it needs.
    error InfoMarketUnauthorized(address caller, bytes32 role);

    /// @notice Registrations, reveals and deposits are paused.
    error InfoMarketPaused();

    /// @notice `registrar` already approved this (robot, amount).
    /// @param registrar The registrar.
    /// @param robot The robot.
    error InfoMarketAlreadyApproved(address registrar, address robot);

    /// @notice `registrar` already approved `limit` registrations in the current period.
    /// @param registrar The registrar.
    /// @param limit `registrarQuota`.
    error InfoMarketRegistrarQuotaExceeded(address registrar, uint256 limit);

    /// @notice `registrar` has no standing approval of that request about `robot` to cancel.
    /// @param registrar The caller.
    /// @param robot The robot.
    error InfoMarketNotApproved(address registrar, address robot);

    /// @notice The deposit's robot signature does not recover to the robot (for its open round trip).
    /// @param robot The depositing robot.
    /// @param recovered Address the signature recovers to (zero when none).
    error InfoMarketInvalidDepositSignature(address robot, address recovered);

    /// @notice The deposit's acknowledgement is not signed by an account holding the nest role.
    /// @param robot The depositing robot.
    /// @param signer Address the acknowledgement recovers to (zero when none).
    error InfoMarketUnacknowledgedDeposit(address robot, address signer);

    /// @notice `caller` submitted a light contract whose seller is `seller`; only the seller may reveal.
    /// @param caller Sender of the refused reveal.
    /// @param seller Seller named in the offer.
    error InfoMarketUnauthorizedSeller(address caller, address seller);

    /// @notice The reveal came after the agreed last block.
    /// @param maxBlock Last block the light contract allowed.
    /// @param currentBlock Block the reveal would have been included in.
    error InfoMarketExpiredContract(uint64 maxBlock, uint256 currentBlock);

    /// @notice The light contract's last block lies further ahead than `maxValidity` blocks.
    /// @param maxBlock Last block the light contract asks for.
    /// @param limit The furthest block allowed now.
    error InfoMarketValidityTooLong(uint64 maxBlock, uint256 limit);

    /// @notice The buyer's signature does not recover to the buyer named in the light contract.
    /// @param buyer Buyer named in the light contract.
    /// @param recovered Address the signature recovers to (zero when it recovers to none).
    error InfoMarketInvalidBuyerSignature(address buyer, address recovered);

    /// @notice The signature's s lies in the upper half of the curve order (a malleated copy).
    /// @param s The refused s value.
    error InfoMarketMalleableSignature(bytes32 s);

    /// @notice This (site, age, max block, buyer, seller, path hash) sale was already revealed once.
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

    /// @notice The seller's vector (purchased vector minus seller position) has a component of
    /// magnitude 2^47 micro units or more, beyond what the similarity test computes exactly.
    /// @param dx Its x component.
    /// @param dy Its y component.
    error InfoMarketVectorOutOfRange(int256 dx, int256 dy);

    /// @notice The seller already sold `limit` records to this buyer in its current round trip.
    /// @param buyer The buyer.
    /// @param seller The seller.
    /// @param limit `maxRecordsPerSeller`.
    error InfoMarketTooManyRecords(address buyer, address seller, uint256 limit);

    /// @notice The buyer's open round trip already holds `limit` live records.
    /// @param buyer The buyer.
    /// @param limit `maxRecordsPerTrip`.
    error InfoMarketTripFull(address buyer, uint256 limit);

    /// @notice `seller` already sold in `buyer`'s open round trip, and its further record would take room
    /// kept for sellers not yet heard: further records take at most half of the room first records leave,
    /// 2 * `repeats` + first records <= `maxRecordsPerTrip`.
    /// @param buyer The buyer.
    /// @param seller The seller refused.
    /// @param repeats Further records (a seller's second and later) the round trip already holds.
    error InfoMarketTripReserved(address buyer, address seller, uint256 repeats);

    /// @notice The light contract was signed for another of the buyer's round trips (a reveal must land
    /// before the buyer's next deposit).
    /// @param buyer The buyer.
    /// @param signed The round trip the buyer signed for.
    /// @param current The buyer's open round trip.
    error InfoMarketWrongTrip(address buyer, uint64 signed, uint64 current);

    /// @notice `robot` was never registered by the market (`grantWealth`).
    /// @param robot The unregistered account.
    error InfoMarketUnregistered(address robot);

    /// @notice `robot` is already registered: the market grants initial wealth once per robot.
    /// @param robot The account.
    error InfoMarketAlreadyRegistered(address robot);

    /// @notice The grant does not cover the bond a registration locks.
    /// @param amount The refused grant.
    /// @param bond `registrationBond`.
    error InfoMarketGrantBelowBond(uint256 amount, uint256 bond);

    /// @notice `robot` has no bond waiting to be withdrawn (it did not `exit`, or its bond is gone).
    /// @param robot The robot.
    error InfoMarketNotExiting(address robot);

    /// @notice `robot` has no revocation that can still be reversed (not revoked, or its appeal window
    /// ended at block `until`).
    /// @param robot The robot.
    /// @param until Last block of the appeal window (0 when not revoked).
    error InfoMarketNotRevoked(address robot, uint64 until);

    /// @notice `robot`'s bond is locked until block `unlockBlock`.
    /// @param robot The robot.
    /// @param unlockBlock First block of `withdrawBond`.
    error InfoMarketBondLocked(address robot, uint256 unlockBlock);

    /// @notice The grant exceeds `maxGrant`.
    /// @param amount The refused grant.
    /// @param limit `maxGrant`.
    error InfoMarketGrantTooLarge(uint256 amount, uint256 limit);

    /// @notice The robot's previous round trip is still being settled: call `settle` first.
    /// @param robot The robot.
    /// @param remaining Records its settlement still has to process.
    error InfoMarketSettlementPending(address robot, uint256 remaining);

    /// @notice There is no deposited round trip of `robot` to settle.
    /// @param robot The robot.
    error InfoMarketNothingToSettle(address robot);

    /// @notice A constructor argument is out of range.
    /// @param parameter Name of the argument (ASCII, right-padded with zeros).
    /// @param value Its value.
    error InfoMarketInvalidParameter(bytes32 parameter, int256 value);

    // ------------------------------------------------------------------------------------------------
    // Constants and configuration
    // ------------------------------------------------------------------------------------------------

    /// @dev One whole information share (the share is a WAD).
    uint256 private constant _WAD = 1e18;
    /// @dev Scale of cos(theta): 1e9 = 1. With components below 2^47, every product of the similarity
    /// test stays below 2^250.
    int256 private constant _COS_SCALE = 1e9;
    int256 private constant _MAX_COMPONENT = 2 ** 47;
    /// @dev Pair comparisons that count as one unit of settlement work: a distinct-seller comparison
    /// costs more (it looks up the other record's seller), so fewer of them make a unit.
    uint256 private constant _PAIRS_PER_UNIT = 64;
    uint256 private constant _DISTINCT_PAIRS_PER_UNIT = 40;
    /// @dev Most live records a round trip may ever hold, and most work units one call may do: the
    /// bounds the declared gas per transaction is measured at (docs/gas.md).
    uint256 private constant _MAX_TRIP_RECORDS = 512;
    uint256 private constant _MAX_SETTLE_BATCH = 48;
    /// @dev Most units of work one settlement can take, with one to spare: a weighing (at most
    /// ceil(512 / 40) = 13 units) and a payment per record. The bounty of them all fits in the share.
    uint256 private constant _MAX_SETTLEMENT_UNITS = _MAX_TRIP_RECORDS * 15;
    /// @dev Scale of an OutlierDistinct weight (distinct sellers / seller's records, as a fixed point).
    uint256 private constant _DISTINCT_SCALE = 1e27;
    /// @dev The site code a void OutlierCapped record takes while weighing: no record is of it, so no
    /// comparison counts it.
    uint256 private constant _VOID = 2;
    /// @dev Under OutlierCapped the reward and the stake stay below this, so that no product of the
    /// payment (amount * (share + 512 stakes) * 512) can overflow.
    uint256 private constant _MAX_CAPPED_AMOUNT = 2 ** 96;
    /// @dev Longest bond delay, blocks: block numbers plus it never overflow 64 bits.
    uint64 private constant _MAX_DELAY = 2 ** 40;
    /// @dev Settlement phases: closed (nothing done yet), weighing, paying.
    uint8 private constant _CLOSED_TRIP = 0;
    uint8 private constant _WEIGH = 1;
    uint8 private constant _PAY = 2;
    /// @dev An identity's life after registration: active (`_registered`), exiting (bond locked until
    /// `_exits[robot].at`), closed (bond returned; the robot may not register again), revoked (bond
    /// burned; reinstated by more registrars than revoked it before `_exits[robot].at`, else for good).
    uint8 private constant _EXITING = 1;
    uint8 private constant _CLOSED = 2;
    uint8 private constant _REVOKED = 3;
    /// @dev An approval withdrawn by its registrar.
    uint256 private constant _CANCELLED = type(uint256).max;

    /// @notice Role that grants and revokes every role (as AccessControl's DEFAULT_ADMIN_ROLE).
    bytes32 public constant ADMIN_ROLE = 0x00;
    /// @notice Role whose holders approve registrations (`grantWealth`).
    bytes32 public constant REGISTRAR_ROLE = keccak256("REGISTRAR_ROLE");
    /// @notice Role whose holders submit deposits (`buyItem`).
    bytes32 public constant DEPOSITOR_ROLE = keccak256("DEPOSITOR_ROLE");
    /// @notice Role whose holders acknowledge deposits (sign `Deposit(robot, trip)`).
    bytes32 public constant NEST_ROLE = keccak256("NEST_ROLE");
    /// @notice Role whose holders pause and unpause.
    bytes32 public constant PAUSER_ROLE = keccak256("PAUSER_ROLE");
    /// @dev secp256k1 order / 2: a larger s is the malleated twin of a valid signature (EIP-2).
    uint256 private constant _HALF_ORDER = 0x7fffffffffffffffffffffffffffffff5d576e7357a4501ddfe92f46681b20a0;

    bytes32 private constant _DOMAIN_TYPEHASH =
        keccak256("EIP712Domain(string name,string version,uint256 chainId,address verifyingContract)");
    bytes32 private constant _OFFER_TYPEHASH =
        keccak256("Offer(address seller,uint8 site,uint32 age,uint64 maxBlock,bytes32 pathHash)");
    bytes32 private constant _ACCEPTANCE_TYPEHASH = keccak256(
        "Acceptance(Offer offer,address buyer,int64 sellerX,int64 sellerY,uint64 trip)"
        "Offer(address seller,uint8 site,uint32 age,uint64 maxBlock,bytes32 pathHash)"
    );
    bytes32 private constant _DEPOSIT_TYPEHASH = keccak256("Deposit(address robot,uint64 trip)");
    bytes32 private constant _NAME_HASH = keccak256("InformationMarket");
    bytes32 private constant _VERSION_HASH = keccak256("4");

    Scheme private immutable _scheme;
    uint256 private immutable _reward;
    uint256 private immutable _informationShare;
    uint256 private immutable _stake;
    int256 private immutable _cosTheta;
    uint64 private immutable _stakeExpiry;
    uint256 private immutable _maxRecordsPerSeller;
    uint256 private immutable _maxRecordsPerTrip;
    uint64 private immutable _maxValidity;
    uint256 private immutable _settleBatch;
    uint64 private immutable _settlementDeadline;
    uint256 private immutable _maxGrant;
    uint256 private immutable _settleBounty;
    uint256 private immutable _registrarThreshold;
    uint256 private immutable _registrarQuota;
    uint64 private immutable _registrarPeriod;
    uint256 private immutable _registrationBond;
    uint64 private immutable _bondDelay;
    uint256 private immutable _cap;
    uint256 private immutable _cachedChainId;
    bytes32 private immutable _cachedDomainSeparator;

    // ------------------------------------------------------------------------------------------------
    // State
    // ------------------------------------------------------------------------------------------------

    uint256 private _totalSupply;
    mapping(address robot => uint256) private _balances;
    /// @dev Stakes locked by the records of each buyer's open round trip.
    mapping(address buyer => uint256) private _pots;
    mapping(address buyer => mapping(uint256 => Information)) private _records;
    mapping(address buyer => Round) private _rounds;
    mapping(address buyer => Settlement) private _settlements;
    /// @dev ((round trip + 1) << 128) | (index of the seller's last record << 64) | records sold in
    /// the round trip, per buyer and seller (0: none yet).
    mapping(address buyer => mapping(address seller => uint256)) private _sold;
    /// @dev ((round trip + 1) << 64) | records of the round trip that were not their seller's first in it,
    /// per buyer (0: none yet).
    mapping(address buyer => uint256) private _repeats;
    mapping(bytes32 key => bool) private _revealed;
    mapping(address robot => bool) private _registered;
    mapping(bytes32 role => mapping(address account => bool)) private _roles;
    /// @dev Per request (keccak256(robot, amount), or keccak256("revoke", robot)): every registrar key that
    /// ever approved it, and the block of each one's approval (`_CANCELLED` once withdrawn). An approval
    /// stands while its key holds the registrar role, held it when approving, and for `registrarPeriod`
    /// blocks.
    mapping(bytes32 request => address[]) private _approvers;
    /// (The approval is packed: (the key's registrar grants when it approved << 64) | block.)
    mapping(bytes32 request => mapping(address registrar => uint256)) private _approvedAt;
    /// @dev How many times an account was granted a role: an approval given under an earlier grant does
    /// not stand.
    mapping(bytes32 role => mapping(address account => uint256)) private _roleGrants;
    /// @dev Approvals (and revocation approvals) each registrar made, and the blocks of its last
    /// `registrarQuota` ones, a ring: a new one is allowed when the one `registrarQuota` back is
    /// `registrarPeriod` blocks old, so no window of that many blocks holds more than the quota.
    mapping(address registrar => uint256) private _quotaUsed;
    mapping(address registrar => mapping(uint256 slot => uint64)) private _quotaBlocks;
    bool private _paused;
    /// @dev Exits: the block from which the bond may be withdrawn (exiting) or until which a revocation
    /// may be reversed (revoked), the identity's state, how many times it was reinstated (revocation
    /// and reinstatement approvals are counted per reinstatement) and whether it was exiting when revoked.
    struct Exit {
        uint64 at;
        uint8 state;
        uint64 reinstated;
        bool exiting;
    }
    mapping(address robot => Exit) private _exits;

    /// @notice Deploys a market with a fixed payment scheme and its trust policy.
    /// @param market_ Account of the market node: it receives the admin, depositor and pauser roles.
    /// @param scheme_ Payment scheme.
    /// @param reward_ Reward R per item, 1e-9 units.
    /// @param informationShare_ Part of R shared with the sellers, as a WAD (0.5 = 5e17); at most 1e18.
    /// @param stake_ Stake per sale, 1e-9 units (0 = no staking); must be 0 under delayed payment.
    /// @param cosTheta_ cos(theta) of the similarity window, in units of 1e-9 (in [-1e9, 1e9]); two
    /// records are similar when the angle between their vectors is strictly less than theta.
    /// @param stakeExpiry_ Blocks after which a round trip's first record expires the round trip (>= 1).
    /// @param maxRecordsPerSeller_ Most records one seller may sell one buyer in one round trip (>= 1).
    /// @param maxRecordsPerTrip_ Most live records a buyer's open round trip may hold (1 to 512).
    /// @param maxValidity_ Furthest a light contract's last block may lie ahead of its reveal (>= 1).
    /// @param settleBatch_ Work units of one `buyItem`, `settle` or `refundExpired` call (1 to 48).
    /// @param settlementDeadline_ Blocks after `buyItem` from which any caller, registered or not, earns
    /// the bounty for continuing an unfinished settlement (>= 1); the rule it pays by never changes.
    /// @param maxGrant_ Most initial wealth the market may grant one robot, 1e-9 units.
    /// @param registrars_ Accounts that receive the registrar role (at least `registrarThreshold_`).
    /// @param registrarThreshold_ Distinct registrar approvals that register a robot (>= 1).
    /// @param registrarQuota_ Most approvals one registrar may make per period (>= 1).
    /// @param registrarPeriod_ Length of that period, blocks (>= 1).
    /// @param nest_ Account that receives the nest role (acknowledges deposits).
    /// @param settleBounty_ Paid to a registered robot per unit of settlement work it does, 1e-9 units;
    /// the bounty of the largest settlement must fit in the reward's share.
    /// @param registrationBond_ Bond every registration locks out of the grant, 1e-9 units (at most
    /// `maxGrant_`).
    /// @param bondDelay_ Blocks between a robot's `exit` and the return of its bond (1 to 2^40): the time the
    /// registrars have to revoke it.
    /// @param cap_ Under OutlierCapped, most records per seller that count in a round trip (>= 1; the
    /// reward and the stake below 2^96 units); 0 under every other scheme.
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
        _grantRole(ADMIN_ROLE, market_);
        _grantRole(DEPOSITOR_ROLE, market_);
        _grantRole(PAUSER_ROLE, market_);
        _grantRole(NEST_ROLE, nest_);
        for (uint256 i; i < registrars_.length; ++i) {
            if (registrars_[i] == address(0)) revert InfoMarketInvalidParameter("registrars", int256(i));
            _grantRole(REGISTRAR_ROLE, registrars_[i]);
        }
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
        _cachedChainId = block.chainid;
        _cachedDomainSeparator = _buildDomainSeparator();
    }

    // ------------------------------------------------------------------------------------------------
    // Market functions
    // ------------------------------------------------------------------------------------------------

    /// @notice Approves registering `robot` with `amount` tokens of initial wealth (0 allowed); the
    /// `registrarThreshold`-th distinct registrar to approve the same (robot, amount) registers it and
    /// mints the grant. Only registered robots may buy, sell or deposit.
    /// The registration locks `registrationBond` of the grant as the robot's bond.
    /// @dev Requirements: the caller is a registrar within its quota (at most `registrarQuota` approvals
    /// in any `registrarPeriod` consecutive blocks); not paused; `robot` is not registered and never was;
    /// `amount` covers the bond and is at most `maxGrant`; the caller's approval of this (robot, amount)
    /// does not stand already. Only standing approvals count (`_stands`). Emits {RegistrationApproved}, and
    /// {WealthGranted} and {BondLocked} when it registers.
    /// @param robot Receiving account.
    /// @param amount Tokens, 1e-9 units.
    /// @return registered Whether this approval registered the robot.
    function grantWealth(address robot, uint256 amount) external returns (bool registered) {
        _requireRole(REGISTRAR_ROLE);
        _requireNotPaused();
        if (_registered[robot] || _exits[robot].state != 0) revert InfoMarketAlreadyRegistered(robot);
        if (amount > _maxGrant) revert InfoMarketGrantTooLarge(amount, _maxGrant);
        if (amount < _registrationBond) revert InfoMarketGrantBelowBond(amount, _registrationBond);
        uint256 count = _approve(keccak256(abi.encode(robot, amount)), robot);
        emit RegistrationApproved(msg.sender, robot, amount, count);
        if (count < _registrarThreshold) return false;
        registered = true;
        _registered[robot] = true;
        _balances[robot] += amount - _registrationBond;
        _totalSupply += amount;
        emit WealthGranted(robot, amount);
        emit BondLocked(robot, _registrationBond);
    }

    /// @notice The caller leaves the market: it may no longer buy, sell or deposit, and its bond comes
    /// back with `withdrawBond` from `bondDelay` blocks on, unless the registrars revoke it meanwhile.
    /// Its sales still pending are paid as usual.
    /// @dev Requirements: the caller is registered. Emits {ExitRequested}.
    function exit() external {
        if (!_registered[msg.sender]) revert InfoMarketUnregistered(msg.sender);
        _registered[msg.sender] = false;
        uint64 at = uint64(block.number) + _bondDelay;
        _exits[msg.sender] = Exit(at, _EXITING, _exits[msg.sender].reinstated, false);
        emit ExitRequested(msg.sender, at);
    }

    /// @notice Returns `robot`'s bond to its balance after its exit delay; anyone may call it.
    /// @dev Requirements: `robot` exited and was not revoked; the delay has passed. Emits {BondReturned}.
    /// @param robot The exited robot.
    /// @return amount The bond returned, 1e-9 units.
    function withdrawBond(address robot) external returns (uint256 amount) {
        Exit storage e = _exits[robot];
        if (e.state != _EXITING) revert InfoMarketNotExiting(robot);
        if (block.number < e.at) revert InfoMarketBondLocked(robot, e.at);
        e.state = _CLOSED;
        amount = _registrationBond;
        _balances[robot] += amount;
        emit BondReturned(robot, amount);
    }

    /// @notice Approves revoking `robot` (registered, or exited within its bond delay); the
    /// `registrarThreshold`-th distinct registrar to approve revokes it: it may no longer buy, sell or
    /// deposit, nor register again, and its bond is burned, unless more registrars reverse it within
    /// `bondDelay` blocks (`reinstate`). Works while paused.
    /// @dev Requirements: the caller is a registrar within its quota (as for `grantWealth`) whose approval of
    /// revoking `robot` does not stand already (only standing approvals count); `robot`
    /// holds a bond. Emits {RevocationApproved}, and {BondForfeited} when it revokes.
    /// @param robot The robot.
    /// @return revoked Whether this approval revoked it.
    function revokeRegistration(address robot) external returns (bool revoked) {
        _requireRole(REGISTRAR_ROLE);
        Exit storage e = _exits[robot];
        if (!_registered[robot] && e.state != _EXITING) revert InfoMarketUnregistered(robot);
        uint256 count = _approve(keccak256(abi.encode("revoke", robot, e.reinstated)), robot);
        emit RevocationApproved(msg.sender, robot, count);
        revoked = count >= _registrarThreshold;
        if (!revoked) return false;
        _registered[robot] = false;
        e.exiting = e.state == _EXITING;
        e.state = _REVOKED;
        e.at = uint64(block.number) + _bondDelay;
        _totalSupply -= _registrationBond;
        emit BondForfeited(robot, _registrationBond);
    }

    /// @notice Approves reversing `robot`'s revocation, within `bondDelay` blocks of it; the
    /// (`registrarThreshold` + 1)-th distinct registrar to approve reinstates it: registered again (or
    /// exiting again, its bond withdrawable `bondDelay` blocks later, when it was exiting), its bond
    /// minted back. More registrars must agree to reverse a revocation than to make one, so the keys
    /// that revoked cannot undo an honest majority's revocation, and a revocation by compromised keys is
    /// reversed by the others once the admin has replaced those keys. Works while paused.
    /// @dev Requirements: the caller is a registrar within its quota (reinstatements count against it as
    /// revocations do) whose approval does not stand already; `robot` was revoked less than `bondDelay`
    /// blocks ago. Approvals of revoking and of reinstating a robot count anew after each reinstatement.
    /// Emits {ReinstatementApproved}, and {RegistrationReinstated} when it reinstates.
    /// @param robot The robot.
    /// @return reinstated Whether this approval reinstated it.
    function reinstate(address robot) external returns (bool reinstated) {
        _requireRole(REGISTRAR_ROLE);
        Exit storage e = _exits[robot];
        if (e.state != _REVOKED || block.number >= e.at) revert InfoMarketNotRevoked(robot, e.at);
        uint256 count = _approve(keccak256(abi.encode("reinstate", robot, e.reinstated)), robot);
        emit ReinstatementApproved(msg.sender, robot, count);
        reinstated = count > _registrarThreshold;
        if (!reinstated) return false;
        e.reinstated += 1;
        if (e.exiting) {
            e.state = _EXITING;
            e.at = uint64(block.number) + _bondDelay;
        } else {
            e.state = 0;
            e.at = 0;
            _registered[robot] = true;
        }
        _totalSupply += _registrationBond;
        emit RegistrationReinstated(robot, _registrationBond);
    }

    /// @notice Withdraws the caller's standing approval of registering `robot` with `amount`.
    /// @dev Requirements: the approval stands. Emits {ApprovalCancelled}.
    /// @param robot The robot.
    /// @param amount The grant approved.
    function cancelApproval(address robot, uint256 amount) external {
        _cancel(keccak256(abi.encode(robot, amount)), robot);
    }

    /// @notice Withdraws the caller's standing approval of revoking `robot`.
    /// @dev Requirements: the approval stands. Emits {ApprovalCancelled}.
    /// @param robot The robot.
    function cancelRevocation(address robot) external {
        _cancel(keccak256(abi.encode("revoke", robot, _exits[robot].reinstated)), robot);
    }

    function _cancel(bytes32 request, address robot) private {
        if (!_stands(msg.sender, _approvedAt[request][msg.sender])) {
            revert InfoMarketNotApproved(msg.sender, robot);
        }
        _approvedAt[request][msg.sender] = _CANCELLED;
        emit ApprovalCancelled(msg.sender, robot, request);
    }

    /// @notice Buys the item `robot` deposited: pays it the reward, closes its round trip and settles
    /// up to `settleBatch` records of it; `settle` finishes the rest.
    /// @dev The reward share and the pot go into the settlement's escrow. Settling weighs every record
    /// of the round trip (expired or not: a deposit is a prompt one) and pays each floor(amount * w / sum w);
    /// the remainder goes back to `robot`, so the supply changes by exactly the reward.
    /// Requirements: the caller is a depositor; not paused; the robot is registered; its previous round
    /// trip is fully settled; the evidence holds the robot's signature over `Deposit(robot, trip)` for
    /// its open round trip and a nest's signature over the same. Emits {ItemBought}, then what
    /// {settle} emits.
    /// @param robot The depositing robot.
    /// @param evidence The robot's and the nest's signatures.
    /// @return done Whether the round trip is fully settled.
    function buyItem(address robot, DepositEvidence calldata evidence) external returns (bool done) {
        _requireRole(DEPOSITOR_ROLE);
        _requireNotPaused();
        if (!_registered[robot]) revert InfoMarketUnregistered(robot);
        Settlement storage s = _settlements[robot];
        if (s.end != 0) revert InfoMarketSettlementPending(robot, s.end - s.next);
        Round storage round = _rounds[robot];
        bytes32 digest = depositDigest(robot, round.trip);
        address signer = _recover(digest, evidence.robotV, evidence.robotR, evidence.robotS);
        if (signer == address(0) || signer != robot) revert InfoMarketInvalidDepositSignature(robot, signer);
        signer = _recover(digest, evidence.nestV, evidence.nestR, evidence.nestS);
        if (signer == address(0) || !_roles[NEST_ROLE][signer]) revert InfoMarketUnacknowledgedDeposit(robot, signer);
        uint256 share = (_reward * _informationShare) / _WAD;
        // The robot receives the reward and escrows the share: never negative since share <= reward.
        _balances[robot] += _reward - share;
        _totalSupply += _reward;
        emit ItemBought(robot, _reward, _pots[robot], round.count - round.first);
        done = _close(robot, share, _settleBatch);
    }

    /// @notice Continues the settlement of `robot`'s deposited round trip for at most `maxRecords`
    /// records of work; anyone may call it (it moves money only by the market's rules), and a
    /// registered caller (any caller from `settlementDeadline` blocks after the deposit) earns `settleBounty`
    /// per unit of work, from the share.
    /// @dev Requirements: a settlement is pending. Emits {RewardShared},
    /// {SettlementBountyPaid} and, at the end, {SettlementCompleted}.
    /// @param robot The depositing robot.
    /// @param maxRecords Work bound, capped at `settleBatch`: each record paid counts one,
    /// each record weighed ceil(m / 64) for m live records (at least one record is weighed when the
    /// bound is `settleBatch`, so the default batch always makes progress).
    /// @return done Whether the round trip is now fully settled.
    function settle(address robot, uint256 maxRecords) external returns (bool done) {
        if (_settlements[robot].end == 0) revert InfoMarketNothingToSettle(robot);
        return _settle(robot, maxRecords < _settleBatch ? maxRecords : _settleBatch);
    }

    /// @notice Settles `buyer`'s open round trip once it can no longer be deposited in time: its first
    /// record opened `stakeExpiry` blocks ago or more, or the buyer is no longer registered (revoked or
    /// exited, it can never deposit). The round trip is closed as a deposit closes it, and every record
    /// is weighed and paid as a prompt deposit would pay it, from its stakes and the reward's share,
    /// which the buyer pays from its balance as far as that goes; the buyer's next deposit starts a new
    /// round trip and keeps the whole reward when that one is empty. So a seller is never better off
    /// because its records expired, and a buyer that waits for expiry still pays the share. Anyone may
    /// call it; a registered caller earns the bounty, as for `settle`, which finishes the rest.
    /// @dev Requirements: no settlement of `buyer` is pending (`settle` it first). Does nothing (returns
    /// 0) when the round trip is empty or has not expired. Emits {RoundTripExpired}, then what {settle} emits.
    /// @param buyer The buyer.
    /// @param maxRecords Work bound of this call, as for `settle` (capped at `settleBatch`).
    /// @return refunded How many records the closed round trip holds.
    function refundExpired(address buyer, uint256 maxRecords) external returns (uint256 refunded) {
        Round storage round = _rounds[buyer];
        uint64 first = round.first;
        uint64 end = round.count;
        if (end == first) return 0;
        if (_registered[buyer] && !_expired(_records[buyer][first].openedAt, block.number)) return 0;
        Settlement storage s = _settlements[buyer];
        if (s.end != 0) revert InfoMarketSettlementPending(buyer, s.end - s.next);
        uint256 share = (_reward * _informationShare) / _WAD;
        uint256 balance = _balances[buyer];
        if (share > balance) share = balance;
        _balances[buyer] = balance - share;
        emit RoundTripExpired(buyer, share, _pots[buyer], end - first);
        _close(buyer, share, maxRecords < _settleBatch ? maxRecords : _settleBatch);
        refunded = end - first;
    }

    // ------------------------------------------------------------------------------------------------
    // Roles and pause
    // ------------------------------------------------------------------------------------------------

    /// @notice Gives `role` to `account` (a second key, or the new key of a rotation).
    /// @dev Requirements: the caller is an admin. Emits {RoleGranted} when it was not held.
    /// @param role The role.
    /// @param account The account.
    function grantRole(bytes32 role, address account) external {
        _requireRole(ADMIN_ROLE);
        _grantRole(role, account);
    }

    /// @notice Takes `role` from `account` (the old key of a rotation, or a compromised one).
    /// @dev Requirements: the caller is an admin. Emits {RoleRevoked} when it was held.
    /// @param role The role.
    /// @param account The account.
    function revokeRole(bytes32 role, address account) external {
        _requireRole(ADMIN_ROLE);
        _revokeRole(role, account);
    }

    /// @notice Gives up `role` held by the caller.
    /// @param role The role.
    function renounceRole(bytes32 role) external {
        _revokeRole(role, msg.sender);
    }

    /// @notice Stops (`paused_` true) or resumes registrations, reveals and deposits. Settlements and
    /// expiries (`refundExpired`) never stop.
    /// @dev Requirements: the caller is a pauser. Emits {PauseSet} when the state changes.
    /// @param paused_ The new state.
    function setPaused(bool paused_) external {
        _requireRole(PAUSER_ROLE);
        if (_paused == paused_) return; // nothing changes: no event
        _paused = paused_;
        emit PauseSet(msg.sender, paused_);
    }

    // ------------------------------------------------------------------------------------------------
    // Seller function
    // ------------------------------------------------------------------------------------------------

    /// @notice Executes a light contract: records the sale under the buyer, reveals the path information
    /// and locks the seller's stake.
    /// @dev Checks, each with its own error: the seller is the caller; the current block is at most the
    /// agreed max block, which lies at most `maxValidity` blocks ahead; buyer and seller are registered;
    /// the buyer's EIP-712 signature over the acceptance is valid and not malleable; it names the
    /// buyer's open round trip; (site, age, max block, buyer, seller, path hash) was never revealed
    /// before; not paused; the information hashes to the committed value; the seller's vector is in range; the
    /// round trip holds fewer than `maxRecordsPerTrip` live records; the seller has not reached
    /// `maxRecordsPerSeller` in this round trip; it can lock the stake.
    /// Emits {StakeLocked} (under staking) and {InformationRevealed}.
    /// @param lc The double-signed light contract.
    /// @param info The path information in the buyer's frame.
    function revealInformation(LightContract calldata lc, PathInfo calldata info) external {
        _requireNotPaused();
        Offer calldata offer = lc.offer;
        address seller = offer.seller;
        address buyer = lc.buyer;
        if (msg.sender != seller) revert InfoMarketUnauthorizedSeller(msg.sender, seller);
        if (block.number > offer.maxBlock) revert InfoMarketExpiredContract(offer.maxBlock, block.number);
        if (offer.maxBlock > block.number + _maxValidity) {
            revert InfoMarketValidityTooLong(offer.maxBlock, block.number + _maxValidity);
        }
        if (buyer == seller) revert InfoMarketSelfDealing(seller);
        if (offer.site > 1) revert InfoMarketInvalidSite(offer.site);
        if (!_registered[seller]) revert InfoMarketUnregistered(seller);
        if (!_registered[buyer]) revert InfoMarketUnregistered(buyer);

        _checkBuyerSignature(lc);
        Round storage round = _rounds[buyer];
        if (lc.trip != round.trip) revert InfoMarketWrongTrip(buyer, lc.trip, round.trip);

        bytes32 key = revealKey(offer.site, offer.age, offer.maxBlock, buyer, seller, offer.pathHash);
        if (_revealed[key]) revert InfoMarketAlreadyRevealed(key);
        _revealed[key] = true;

        bytes32 revealed = keccak256(abi.encode(info.x, info.y, info.salt));
        if (revealed != offer.pathHash) revert InfoMarketInformationMismatch(offer.pathHash, revealed);

        (int64 dx, int64 dy) = _sellerVector(info.x, info.y, lc.sellerX, lc.sellerY);
        uint64 index = round.count;
        if (index - round.start >= _maxRecordsPerTrip) revert InfoMarketTripFull(buyer, _maxRecordsPerTrip);
        uint16 prevGap = _countSale(buyer, seller, index);

        uint256 stake_ = _stake;
        if (stake_ > 0) {
            uint256 balance = _balances[seller];
            if (balance < stake_) revert InfoMarketInsufficientStake(seller, balance, stake_);
            _balances[seller] = balance - stake_;
            _pots[buyer] += stake_;
            emit StakeLocked(seller, buyer, stake_);
        }

        _records[buyer][index] = Information(seller, uint64(block.number), offer.site, dx, dy, 0, prevGap);
        round.count = index + 1;
        emit InformationRevealed(
            buyer, seller, key, index, offer.site, offer.age, info.x, info.y, lc.sellerX, lc.sellerY, offer.pathHash
        );
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

    /// @notice Stakes and shares locked under `buyer`: the pot of its open round trip plus what its
    /// pending settlement still holds.
    /// @param buyer The account.
    /// @return The locked amount, 1e-9 units.
    function lockedStake(address buyer) external view returns (uint256) {
        return _pots[buyer] + _settlements[buyer].escrow;
    }

    /// @notice Whether `robot` has a deposited round trip still to settle, and where it stands.
    /// @param robot The account.
    /// @return pending True until the settlement completes.
    /// @return phase 0 closed (nothing done yet), 1 weighing, 2 paying.
    /// @return remaining Records left in the current phase.
    function pendingSettlement(address robot) external view returns (bool pending, uint8 phase, uint256 remaining) {
        Settlement storage s = _settlements[robot];
        if (s.end == 0) return (false, 0, 0);
        return (true, s.phase, s.end - s.next);
    }

    /// @notice Tokens in existence: all balances plus everything locked.
    /// @return The supply, 1e-9 units.
    function totalSupply() external view returns (uint256) {
        return _totalSupply;
    }

    /// @notice Decimals of the token amounts (1 token = 1e9 units).
    /// @return Always 9.
    function decimals() external pure returns (uint8) {
        return 9;
    }

    /// @notice The records of `buyer`'s open round trip (not yet deposited nor expired), in reveal order.
    /// @param buyer The account.
    /// @return list Its contributors' records.
    function contributors(address buyer) external view returns (Information[] memory list) {
        Round storage round = _rounds[buyer];
        uint256 start = round.start;
        list = new Information[](round.count - start);
        for (uint256 i; i < list.length; ++i) list[i] = _records[buyer][start + i];
    }

    /// @notice The round trip of `buyer` that light contracts signed now belong to (it grows by one at
    /// each of the buyer's deposits).
    /// @param buyer The account.
    /// @return The open round trip's number.
    function roundTrip(address buyer) external view returns (uint64) {
        return _rounds[buyer].trip;
    }

    /// @notice Whether `account` holds `role`.
    /// @param role The role.
    /// @param account The account.
    /// @return True when held.
    function hasRole(bytes32 role, address account) external view returns (bool) {
        return _roles[role][account];
    }

    /// @notice Whether registrations, reveals and deposits are paused.
    /// @return True when paused.
    function paused() external view returns (bool) {
        return _paused;
    }

    /// @notice Approvals the registration of `robot` with `amount` has so far.
    /// @param robot The robot.
    /// @param amount The grant.
    /// @return The number of distinct registrars that approved it.
    function approvals(address robot, uint256 amount) external view returns (uint256) {
        return _standing(keccak256(abi.encode(robot, amount)));
    }

    /// @notice The EIP-712 digest a robot and a nest sign for the deposit that ends round trip `trip`.
    /// @param robot The depositing robot.
    /// @param trip Its round trip.
    /// @return The digest of `Deposit(robot, trip)`.
    function depositDigest(address robot, uint64 trip) public view returns (bytes32) {
        return keccak256(
            abi.encodePacked(hex"1901", _domainSeparator(), keccak256(abi.encode(_DEPOSIT_TYPEHASH, robot, trip)))
        );
    }

    /// @notice Whether the market registered `robot`.
    /// @param robot The account.
    /// @return True once registered.
    function isRegistered(address robot) external view returns (bool) {
        return _registered[robot];
    }

    /// @notice Whether the light contract identified by `key` was already revealed.
    /// @param key A `revealKey`.
    /// @return True once revealed.
    function isRevealed(bytes32 key) external view returns (bool) {
        return _revealed[key];
    }

    /// @notice Whether two seller vectors are similar: the angle between them is strictly less than
    /// theta. Exposed so that clients and tests can check the rule on its own; components must be below
    /// 2^47 in magnitude, as on the reveal path (`InfoMarketVectorOutOfRange` otherwise).
    /// @param ax First vector, x.
    /// @param ay First vector, y.
    /// @param bx Second vector, x.
    /// @param by Second vector, y.
    /// @return Whether they are similar.
    function similar(int64 ax, int64 ay, int64 bx, int64 by) external view returns (bool) {
        (ax, ay) = _sellerVector(ax, ay, 0, 0);
        (bx, by) = _sellerVector(bx, by, 0, 0);
        return _similar(ax, ay, _norm2(ax, ay), bx, by, _norm2(bx, by), _cosTheta);
    }

    /// @notice The identity of a sale for the never-twice check: the paper's tuple and the committed
    /// information, so two different sales with the same (site, age, max block) are both allowed.
    /// @param site Site code.
    /// @param age Information age.
    /// @param maxBlock Agreed last block.
    /// @param buyer Buyer.
    /// @param seller Seller.
    /// @param pathHash The commitment.
    /// @return `keccak256(abi.encode(site, age, maxBlock, buyer, seller, pathHash))`.
    function revealKey(uint8 site, uint32 age, uint64 maxBlock, address buyer, address seller, bytes32 pathHash)
        public
        pure
        returns (bytes32)
    {
        return keccak256(abi.encode(site, age, maxBlock, buyer, seller, pathHash));
    }

    /// @notice The EIP-712 digest the buyer signs to accept `offer` (for clients to cross-check).
    /// @param offer The offer.
    /// @param buyer The buyer.
    /// @param sellerX Seller's position in the buyer's frame, x.
    /// @param sellerY Same, y.
    /// @param trip The buyer's round trip.
    /// @return The digest.
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

    /// @notice The EIP-712 domain (EIP-5267), so that clients sign for this contract on this chain only.
    /// @return fields Bit mask of the fields used (name, version, chainId, verifyingContract).
    /// @return name "InformationMarket".
    /// @return version "4".
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
        return (hex"0f", "InformationMarket", "4", block.chainid, address(this), bytes32(0), new uint256[](0));
    }

    /// @notice The market's configuration (the constructor's economic arguments; `policy` has the rest).
    /// @return scheme_ Payment scheme.
    /// @return reward_ Reward per item, 1e-9 units.
    /// @return informationShare_ Shared part of the reward, WAD.
    /// @return stake_ Stake per sale, 1e-9 units.
    /// @return cosTheta_ cos(theta), 1e-9 units.
    /// @return stakeExpiry_ Blocks before a record expires.
    /// @return maxRecordsPerSeller_ Most records per seller, buyer and round trip.
    /// @return maxRecordsPerTrip_ Most live records per round trip.
    /// @return maxValidity_ Furthest a light contract's last block may lie ahead.
    /// @return settleBatch_ Work units per call.
    /// @return settlementDeadline_ Blocks after a deposit from which any caller earns the settle bounty.
    /// @return maxGrant_ Most initial wealth per robot.
    /// @return settleBounty_ Bounty per unit of settlement work.
    /// @return cap_ Most records per seller that count in a round trip under OutlierCapped (0 otherwise).
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

    /// @notice The registration policy.
    /// @return threshold Distinct registrar approvals that register (or revoke) a robot.
    /// @return quota Most approvals per registrar per period.
    /// @return period Its length, blocks.
    /// @return bond Bond a registration locks, 1e-9 units.
    /// @return bondDelay Blocks from a robot's exit to the return of its bond.
    function policy()
        external
        view
        returns (uint256 threshold, uint256 quota, uint64 period, uint256 bond, uint64 bondDelay)
    {
        return (_registrarThreshold, _registrarQuota, _registrarPeriod, _registrationBond, _bondDelay);
    }

    /// @notice The bond `robot` has locked (registered, or exited and not yet withdrawn; 0 otherwise).
    /// @param robot The account.
    /// @return The bond, 1e-9 units.
    function bondOf(address robot) external view returns (uint256) {
        return _registered[robot] || _exits[robot].state == _EXITING ? _registrationBond : 0;
    }

    // ------------------------------------------------------------------------------------------------
    // Internal
    // ------------------------------------------------------------------------------------------------

    function _requireRole(bytes32 role) private view {
        if (!_roles[role][msg.sender]) revert InfoMarketUnauthorized(msg.sender, role);
    }

    function _requireNotPaused() private view {
        if (_paused) revert InfoMarketPaused();
    }

    function _grantRole(bytes32 role, address account) private {
        if (!_roles[role][account]) {
            _roles[role][account] = true;
            ++_roleGrants[role][account];
            emit RoleGranted(role, account, msg.sender);
        }
    }

    function _revokeRole(bytes32 role, address account) private {
        if (_roles[role][account]) {
            _roles[role][account] = false;
            emit RoleRevoked(role, account, msg.sender);
        }
    }

    /// @dev Records the caller's approval of `request` about `robot`, within its quota; returns how many
    /// approvals of it stand. A registrar whose approval stands may not approve again; one whose approval
    /// lapsed, was cancelled or predates its role may.
    function _approve(bytes32 request, address robot) private returns (uint256) {
        uint256 at = _approvedAt[request][msg.sender];
        if (at == 0) _approvers[request].push(msg.sender);
        else if (_stands(msg.sender, at)) revert InfoMarketAlreadyApproved(msg.sender, robot);
        uint256 used = _quotaUsed[msg.sender];
        uint256 slot = used % _registrarQuota;
        if (used >= _registrarQuota && uint256(_quotaBlocks[msg.sender][slot]) + _registrarPeriod > block.number) {
            revert InfoMarketRegistrarQuotaExceeded(msg.sender, _registrarQuota);
        }
        _quotaBlocks[msg.sender][slot] = uint64(block.number);
        _quotaUsed[msg.sender] = used + 1;
        _approvedAt[request][msg.sender] = (_roleGrants[REGISTRAR_ROLE][msg.sender] << 64) | block.number;
        return _standing(request);
    }

    /// @dev How many approvals of `request` stand (one per registrar key that approved it).
    function _standing(bytes32 request) private view returns (uint256 count) {
        address[] storage list = _approvers[request];
        for (uint256 i; i < list.length; ++i) {
            if (_stands(list[i], _approvedAt[request][list[i]])) ++count;
        }
    }

    /// @dev Whether `registrar`'s approval `at` ((grants << 64) | block) stands: given and not withdrawn,
    /// while the key holds the registrar role under the grant it approved under, less than
    /// `registrarPeriod` blocks ago.
    function _stands(address registrar, uint256 at) private view returns (bool) {
        return at != 0 && at != _CANCELLED && _roles[REGISTRAR_ROLE][registrar]
            && at >> 64 == _roleGrants[REGISTRAR_ROLE][registrar] && (at & type(uint64).max) + _registrarPeriod > block.number;
    }

    /// @dev The signer of `digest`, refusing the malleated (high-s) twin of a signature; zero when none.
    function _recover(bytes32 digest, uint8 v, bytes32 r, bytes32 s) private pure returns (address) {
        if (uint256(s) > _HALF_ORDER) revert InfoMarketMalleableSignature(s);
        return ecrecover(digest, v, r, s);
    }

    function _checkBuyerSignature(LightContract calldata lc) private view {
        bytes32 digest = acceptanceDigest(lc.offer, lc.buyer, lc.sellerX, lc.sellerY, lc.trip);
        address recovered = _recover(digest, lc.v, lc.r, lc.s);
        if (recovered == address(0) || recovered != lc.buyer) revert InfoMarketInvalidBuyerSignature(lc.buyer, recovered);
    }

    /// @dev The seller's rotated vector (docs/model.md §4: purchased vector minus seller position),
    /// range-checked, a zero vector replaced by (1, 0).
    function _sellerVector(int64 x, int64 y, int64 sx, int64 sy) private pure returns (int64, int64) {
        int256 dx = int256(x) - sx;
        int256 dy = int256(y) - sy;
        if (dx >= _MAX_COMPONENT || dx <= -_MAX_COMPONENT || dy >= _MAX_COMPONENT || dy <= -_MAX_COMPONENT) {
            revert InfoMarketVectorOutOfRange(dx, dy);
        }
        return _nonZero(int64(dx), int64(dy));
    }

    function _nonZero(int64 x, int64 y) private pure returns (int64, int64) {
        return x == 0 && y == 0 ? (int64(1), int64(0)) : (x, y);
    }

    /// @dev Counts a sale of `seller` to `buyer` in the buyer's open round trip, within the bound, as
    /// record `index`; returns how far back the seller's previous record of the round trip lies (0 when
    /// none, or when it is too far back to be live: a live window is at most 512 records).
    /// A seller's further record (not its first in the round trip) is refused when it would take more
    /// than half of the room the first records leave, so that colluders cannot fill a round trip with
    /// repeated sales: a seller not yet heard is refused only when at least half of `maxRecordsPerTrip`
    /// distinct sellers sold in it.
    function _countSale(address buyer, address seller, uint64 index) private returns (uint16 prevGap) {
        Round storage round = _rounds[buyer];
        uint256 trip = round.trip;
        uint256 packed = _sold[buyer][seller];
        bool same = packed >> 128 == trip + 1;
        uint256 n = same ? packed & type(uint64).max : 0;
        if (n >= _maxRecordsPerSeller) revert InfoMarketTooManyRecords(buyer, seller, _maxRecordsPerSeller);
        if (same) {
            uint256 gap = index - ((packed >> 64) & type(uint64).max);
            if (gap <= _MAX_TRIP_RECORDS) prevGap = uint16(gap);
            uint256 rp = _repeats[buyer];
            uint256 repeats = rp >> 64 == trip + 1 ? rp & type(uint64).max : 0;
            uint256 firsts = index - round.first - repeats;
            if (2 * (repeats + 1) + firsts > _maxRecordsPerTrip) revert InfoMarketTripReserved(buyer, seller, repeats);
            _repeats[buyer] = ((trip + 1) << 64) | (repeats + 1);
        }
        _sold[buyer][seller] = ((trip + 1) << 128) | (uint256(index) << 64) | (n + 1);
    }

    function _expired(uint64 openedAt, uint256 now_) private view returns (bool) {
        return uint256(openedAt) + _stakeExpiry <= now_;
    }

    /// @dev Closes `robot`'s open round trip (by a deposit or by its expiry) into a settlement whose
    /// escrow holds `share` and the round trip's stakes, and runs it for `budget` units of work.
    function _close(address robot, uint256 share, uint256 budget) private returns (bool) {
        Settlement storage s = _settlements[robot];
        Round storage round = _rounds[robot];
        uint256 pot = _pots[robot];
        _pots[robot] = 0;
        uint64 first = round.first;
        uint64 end = round.count;
        round.start = end;
        round.first = end;
        round.trip += 1;
        s.next = first;
        s.end = end;
        s.closedAt = uint64(block.number);
        s.live = first;
        s.phase = _CLOSED_TRIP;
        s.first = first;
        s.escrow = share + pot;
        return _settle(robot, budget);
    }

    /// @dev Runs the pending settlement of `robot` for at most `budget` units of work, phase by phase:
    /// weigh the records, pay every record of the round trip by weight; then return the rest. However
    /// late it is finished, the records are weighed as a prompt settlement weighs them: a seller gains
    /// nothing by a settlement left pending.
    /// A registered caller, and from `settlementDeadline` blocks after the deposit any caller, earns
    /// `settleBounty` per unit: for weighing from the escrow before the paid amount is
    /// fixed, for paying from each record's share.
    function _settle(address robot, uint256 budget) private returns (bool) {
        Settlement storage s = _settlements[robot];
        // Past the settlement deadline the bounty is paid to any caller, registered or not, so that an
        // outside keeper is paid to finish what the robots left.
        bool late = block.number >= uint256(s.closedAt) + _settlementDeadline;
        uint256 rate = _settleBounty != 0 && (_registered[msg.sender] || late) ? _settleBounty : 0;
        uint256 units = budget;
        uint64 next = s.next;
        uint64 end = s.end;
        uint256 escrow = s.escrow;
        uint8 phase = s.phase;
        if (phase == _CLOSED_TRIP) phase = _scheme == Scheme.Delayed ? _PAY : _WEIGH;
        if (phase == _WEIGH) {
            // Weighing one record compares it with every live record: it costs ceil(m / pairs per unit)
            // units of the budget, so a batch's gas stays bounded (m <= 512, docs/gas.md).
            uint256 per = _scheme == Scheme.OutlierDistinct ? _DISTINCT_PAIRS_PER_UNIT : _PAIRS_PER_UNIT;
            uint256 cost = (end - s.live + per - 1) / per;
            if (cost == 0) cost = 1; // no live record: nothing to weigh
            uint256 affordable = budget / cost;
            if (next < end && affordable == 0 && budget == _settleBatch) affordable = 1;
            if (next < end && affordable > 0) {
                uint64 stop = next + uint64(affordable < end - next ? affordable : end - next);
                (uint256 sum, uint256 counted) = _weigh(robot, s.live, next, stop, end);
                s.totalWeight += sum;
                if (_scheme == Scheme.OutlierCapped) s.counted = uint64(counted);
                uint256 spent = (stop - next) * cost;
                budget = spent < budget ? budget - spent : 0;
                next = stop;
            }
            if (next < end) {
                s.phase = _WEIGH;
                return _pause(robot, next, escrow, rate * (units - budget));
            }
            phase = _PAY;
        }
        uint256 bounty;
        uint64 first = s.first;
        uint64 live = s.live;
        if (phase != s.phase) {
            // Paying starts, from the round trip's first record: the work so far is paid from the
            // escrow (never more than it holds: an expired round trip's share may be short), then what
            // the records share is fixed.
            bounty = rate * (units - budget);
            if (bounty > escrow) bounty = escrow;
            escrow -= bounty;
            s.amount = escrow;
            if (_scheme == Scheme.Delayed) s.totalWeight = end - live;
            s.phase = phase;
            next = first;
        }
        uint256 amount = s.amount;
        uint256 total = s.totalWeight;
        bool equal = _scheme == Scheme.Delayed;
        bool capped = !equal && _scheme == Scheme.OutlierCapped;
        while (next < end && budget > 0) {
            Information storage record = _records[robot][next];
            uint256 weight = equal ? 1 : record.weight;
            uint256 share;
            if (capped) {
                (weight, share) = _cappedShare(s, weight, amount, end - live);
            } else {
                share = (amount * weight) / total;
            }
            uint256 cut = rate < share ? rate : share;
            _balances[record.seller] += share - cut;
            escrow -= share;
            bounty += cut;
            emit RewardShared(robot, record.seller, next, weight, share - cut);
            ++next;
            --budget;
        }
        _payBounty(robot, bounty);
        if (next < end) {
            s.next = next;
            s.escrow = escrow;
            return false;
        }
        return _finish(robot, escrow, first < end ? amount - escrow : 0, total);
    }

    /// @dev OutlierCapped: what a live record of count `count` (0: void) is paid of `liveAmount`, and its
    /// weight. A void record weighs its stake, the counted ones share the rest (the share and their own
    /// stakes) by their counts, C their sum: weights stake * C and (share + counted * stake) * count over
    /// C * (share + m * stake) for m live records, as the simulated ledger pays them.
    function _cappedShare(Settlement storage s, uint256 count, uint256 liveAmount, uint256 m)
        private
        view
        returns (uint256 weight, uint256 share)
    {
        uint256 shared = (_reward * _informationShare) / _WAD;
        uint256 sum = s.totalWeight;
        weight = count == 0 ? _stake * sum : (shared + s.counted * _stake) * count;
        uint256 total = sum * (shared + m * _stake);
        share = total == 0 ? 0 : (liveAmount * weight) / total;
    }

    /// @dev Stops a settlement call before paying: records where it stands and pays the bounty.
    function _pause(address robot, uint64 next, uint256 escrow, uint256 bounty) private returns (bool) {
        Settlement storage s = _settlements[robot];
        if (bounty > escrow) bounty = escrow; // an expired round trip's share may be short
        s.next = next;
        s.escrow = escrow - bounty;
        _payBounty(robot, bounty);
        return false;
    }

    function _payBounty(address robot, uint256 bounty) private {
        if (bounty == 0) return;
        _balances[msg.sender] += bounty;
        emit SettlementBountyPaid(msg.sender, robot, bounty);
    }

    /// @dev Ends a settlement: what the escrow still holds goes back to the robot.
    function _finish(address robot, uint256 kept, uint256 shared, uint256 total)
        private
        returns (bool)
    {
        _balances[robot] += kept;
        emit SettlementCompleted(robot, shared, kept, total);
        delete _settlements[robot];
        // When nothing was revealed to the robot since its deposit, its next round trip can start
        // again at index 0 and rewrite warm slots (about 5k gas each) instead of fresh ones (22k). Not
        // when its open round trip holds records: their sellers' links (`_sold`) point at their indices.
        Round storage round = _rounds[robot];
        if (round.count == round.first) {
            round.start = 0;
            round.count = 0;
            round.first = 0;
        }
        return true;
    }

    /// @dev Weights of records [from, to) of `robot` against the live ones [live, end) of the same site.
    /// Outlier: the number of records (itself included) whose vector lies strictly within theta of its
    /// own. OutlierDistinct: the number of distinct sellers with such a record (its own seller once),
    /// times 1e27, divided by its seller's live records for the same site. OutlierCapped: a record
    /// preceded by `cap` live records of its seller is void (weight 0, and compared with nothing); the
    /// others weigh as under Outlier, among the counted records only. Loads the live records once into
    /// memory (one storage slot each): O(end - live) storage reads and O((to - from) * (end - live))
    /// comparisons, bounded by the caller's batch. Returns the weights' sum and, under OutlierCapped, how
    /// many live records count.
    function _weigh(address robot, uint64 live, uint64 from, uint64 to, uint64 end)
        private
        returns (uint256 sum, uint256 counted)
    {
        uint256 m = end - live;
        int256[] memory xs = new int256[](m);
        int256[] memory ys = new int256[](m);
        uint256[] memory norms = new uint256[](m);
        uint256[] memory sites = new uint256[](m);
        // Distinct scheme: each record's seller as a small number (its rank among the live records'
        // sellers, from the chain of previous-record gaps), and each rank's number of live records.
        bool distinct = _scheme == Scheme.OutlierDistinct;
        uint256[] memory rank = new uint256[](distinct ? m : 0);
        uint256[] memory sales = new uint256[](distinct ? 2 * m : 0);
        uint256[] memory mark = new uint256[](distinct ? m : 0);
        uint256 ranks;
        // Capped scheme: each record's place among its seller's live records (0 for the first), from the
        // same chain of gaps; from place `cap` on a record is void.
        bool capped = _scheme == Scheme.OutlierCapped;
        uint256[] memory place = new uint256[](capped ? m : 0);
        mapping(uint256 => Information) storage records = _records[robot];
        for (uint256 k; k < m; ++k) {
            Information storage r = records[live + k];
            (xs[k], ys[k], sites[k]) = (r.dx, r.dy, r.site);
            norms[k] = _norm2(r.dx, r.dy);
            if (distinct) {
                uint256 gap = r.prevGap;
                uint256 q = gap != 0 && gap <= k ? rank[k - gap] : ranks++;
                rank[k] = q;
                ++sales[2 * q + r.site];
            } else if (capped) {
                uint256 gap = r.prevGap;
                uint256 p = gap != 0 && gap <= k ? place[k - gap] + 1 : 0;
                place[k] = p;
                if (p >= _cap) sites[k] = _VOID;
                else ++counted;
            }
        }
        int256 cosTheta = _cosTheta;
        for (uint256 i = from - live; i < to - live; ++i) {
            uint256 w = 1;
            (int256 x, int256 y, uint256 n, uint256 site) = (xs[i], ys[i], norms[i], sites[i]);
            if (distinct) {
                mark[rank[i]] = i + 1; // its own seller counts once, by this record
                for (uint256 j; j < m; ++j) {
                    if (sites[j] != site || mark[rank[j]] == i + 1) continue;
                    if (_similar(x, y, n, xs[j], ys[j], norms[j], cosTheta)) {
                        mark[rank[j]] = i + 1;
                        unchecked {
                            ++w;
                        }
                    }
                }
                w = (w * _DISTINCT_SCALE) / sales[2 * rank[i] + site];
            } else if (site == _VOID) {
                w = 0;
            } else {
                for (uint256 j; j < m; ++j) {
                    if (j == i || sites[j] != site) continue;
                    if (_similar(x, y, n, xs[j], ys[j], norms[j], cosTheta)) {
                        unchecked {
                            ++w;
                        }
                    }
                }
            }
            records[live + i].weight = uint104(w);
            sum += w;
        }
    }

    function _norm2(int256 x, int256 y) private pure returns (uint256) {
        unchecked {
            return uint256(x * x + y * y); // below 2^95: components are below 2^47
        }
    }

    /// @dev angle(a, b) < theta  <=>  a.b > cos(theta) |a| |b|, decided without square roots:
    /// with c = cos(theta) * S (S = 1e9) and d = a.b,
    /// - c >= 0: similar iff d > 0 and d^2 S^2 > c^2 |a|^2 |b|^2;
    /// - c < 0: similar iff d >= 0 or d^2 S^2 < c^2 |a|^2 |b|^2.
    /// Components are below 2^47, so every product is below 2^250: exact integer arithmetic.
    function _similar(int256 ax, int256 ay, uint256 na, int256 bx, int256 by, uint256 nb, int256 c)
        private
        pure
        returns (bool)
    {
        unchecked {
            int256 d = ax * bx + ay * by;
            uint256 lhs = uint256(d * d) * uint256(_COS_SCALE * _COS_SCALE);
            uint256 rhs = uint256(c * c) * na * nb;
            if (c >= 0) return d > 0 && lhs > rhs;
            return d >= 0 || lhs < rhs;
        }
    }

    function _domainSeparator() private view returns (bytes32) {
        return block.chainid == _cachedChainId ? _cachedDomainSeparator : _buildDomainSeparator();
    }

    function _buildDomainSeparator() private view returns (bytes32) {
        return keccak256(abi.encode(_DOMAIN_TYPEHASH, _NAME_HASH, _VERSION_HASH, block.chainid, address(this)));
    }
}
