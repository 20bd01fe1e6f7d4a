"""Payment schemes: weight rules over a buyer's open transactions (registered by ``infomarket.builtins``
through the public ``register_payment``)."""
