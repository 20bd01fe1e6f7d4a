// SPDX-License-Identifier: MIT
pragma solidity 0.8.28;

import {IInformationMarket} from "../IInformationMarket.sol";
import {MarketStorage} from "./MarketStorage.sol";

/// @title MarketRoles
/// @notice Roles and pause: who may call what (as OpenZeppelin's AccessControl: the admin grants and
/// revokes roles, several accounts may hold one) and the switch that stops registrations, reveals and
/// deposits.
/// @dev `_requireRole` and `_requireNotPaused` are the checks every other module calls first. A role
/// grant is counted (`_roleGrants`) so that a registrar's approvals given under an earlier grant no
/// longer stand once its key was revoked and granted again.
abstract contract MarketRoles is MarketStorage {
    /// @inheritdoc IInformationMarket
    bytes32 public constant ADMIN_ROLE = 0x00;

    /// @inheritdoc IInformationMarket
    bytes32 public constant REGISTRAR_ROLE = keccak256("REGISTRAR_ROLE");

    /// @inheritdoc IInformationMarket
    bytes32 public constant DEPOSITOR_ROLE = keccak256("DEPOSITOR_ROLE");

    /// @inheritdoc IInformationMarket
    bytes32 public constant NEST_ROLE = keccak256("NEST_ROLE");

    /// @inheritdoc IInformationMarket
    bytes32 public constant PAUSER_ROLE = keccak256("PAUSER_ROLE");

    /// @dev Gives the market node the admin, depositor and pauser roles, the nest its role and every
    /// registrar the registrar role (a zero registrar is refused).
    constructor(address market_, address nest_, address[] memory registrars_) {
        _grantRole(ADMIN_ROLE, market_);
        _grantRole(DEPOSITOR_ROLE, market_);
        _grantRole(PAUSER_ROLE, market_);
        _grantRole(NEST_ROLE, nest_);
        for (uint256 i; i < registrars_.length; ++i) {
            if (registrars_[i] == address(0)) revert InfoMarketInvalidParameter("registrars", int256(i));
            _grantRole(REGISTRAR_ROLE, registrars_[i]);
        }
    }

    /// @inheritdoc IInformationMarket
    function grantRole(bytes32 role, address account) external {
        _requireRole(ADMIN_ROLE);
        _grantRole(role, account);
    }

    /// @inheritdoc IInformationMarket
    function revokeRole(bytes32 role, address account) external {
        _requireRole(ADMIN_ROLE);
        _revokeRole(role, account);
    }

    /// @inheritdoc IInformationMarket
    function renounceRole(bytes32 role) external {
        _revokeRole(role, msg.sender);
    }

    /// @inheritdoc IInformationMarket
    function setPaused(bool paused_) external {
        _requireRole(PAUSER_ROLE);
        if (_paused == paused_) return; // nothing changes: no event
        _paused = paused_;
        emit PauseSet(msg.sender, paused_);
    }

    /// @inheritdoc IInformationMarket
    function hasRole(bytes32 role, address account) external view returns (bool) {
        return _roles[role][account];
    }

    /// @inheritdoc IInformationMarket
    function paused() external view returns (bool) {
        return _paused;
    }

    function _requireRole(bytes32 role) internal view {
        if (!_roles[role][msg.sender]) revert InfoMarketUnauthorized(msg.sender, role);
    }

    function _requireNotPaused() internal view {
        if (_paused) revert InfoMarketPaused();
    }

    function _grantRole(bytes32 role, address account) internal {
        if (!_roles[role][account]) {
            _roles[role][account] = true;
            ++_roleGrants[role][account];
            emit RoleGranted(role, account, msg.sender);
        }
    }

    function _revokeRole(bytes32 role, address account) internal {
        if (_roles[role][account]) {
            _roles[role][account] = false;
            emit RoleRevoked(role, account, msg.sender);
        }
    }
}
