"""Defence combinations, one runnable experiment each: a buy rule with a payment rule that slashes stakes
(docs/defences.md, "Combinations")."""
