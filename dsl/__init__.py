"""The .fsv language front-end: text to checked, typed scenario IR."""
